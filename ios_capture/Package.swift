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
        .target(name: "SoftDecaCapture"),
        .target(name: "SoftDecaCaptureUI", dependencies: ["SoftDecaCapture"]),
        .executableTarget(name: "softdeca-capture", dependencies: ["SoftDecaCapture"]),
        .testTarget(name: "SoftDecaCaptureTests", dependencies: ["SoftDecaCapture"]),
    ]
)
