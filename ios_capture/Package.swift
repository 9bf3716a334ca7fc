// swift-tools-version:5.9
// SoftDecaCapture: the platform-independent core of the iOS capture app (frames, encoders of the
// project's UDP protocol, Live Link Face and iFacialMocap, the UDP sender, the take recorder),
// built and tested on Linux and macOS. SoftDecaCaptureUI holds the app shell (ARKit, SwiftUI,
// Network.framework); it compiles to nothing where those frameworks are missing.
import PackageDescription

let package = Package(
    name: "SoftDecaCapture",
    platforms: [.iOS(.v16), .macOS(.v13)],
    products: [
        .library(name: "SoftDecaCapture", targets: ["SoftDecaCapture"]),
        .library(name: "SoftDecaCaptureUI", targets: ["SoftDecaCaptureUI"]),
        .executable(name: "softdeca-capture", targets: ["softdeca-capture"]),
    ],
    targets: [
        .target(
            name: "SoftDecaCapture",
            // landmarks_definition.json links to training/softdeca_train/landmarks/definition.json,
            // the landmark file the rest of the repository reads (one source of the indices).
            resources: [.copy("Resources/landmarks_definition.json")]
        ),
        .target(name: "SoftDecaCaptureUI", dependencies: ["SoftDecaCapture"]),
        .executableTarget(name: "softdeca-capture", dependencies: ["SoftDecaCapture"]),
        .testTarget(name: "SoftDecaCaptureTests", dependencies: ["SoftDecaCapture"]),
    ]
)
