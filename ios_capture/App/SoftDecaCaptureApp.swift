// The app's entry point: add this file to an iOS app target that links the package's
// SoftDecaCaptureUI library (ios_capture/README.md says how).
#if canImport(ARKit) && canImport(SwiftUI)
import SoftDecaCaptureUI
import SwiftUI

@main
struct SoftDecaCaptureApp: App {
    var body: some Scene {
        WindowGroup { CaptureRootView() }
    }
}
#endif
