import Foundation
import XCTest
@testable import SoftDecaCapture

/// The Swift package spells ARKit's blendshape names and the Live Link Face values itself (an app
/// bundle reads no repository file); these tests hold those copies to the one definition,
/// plugin/data/face_names.json, that the C++ library and the training package read.
final class FaceNamesTests: XCTestCase {
    private func definition() throws -> [String: Any] {
        let url = TestEnvironment.repoRoot.appendingPathComponent("plugin/data/face_names.json")
        return try JSONSerialization.jsonObject(with: Data(contentsOf: url)) as! [String: Any]
    }

    func testARKitNamesAreTheDefinition() throws {
        XCTAssertEqual(ARKitBlendshapes.names, try definition()["arkit_blendshapes"] as? [String])
        XCTAssertEqual(ARKitBlendshapes.names.count, ARKitBlendshapes.count)
    }

    func testLiveLinkFaceValuesAreTheDefinition() throws {
        XCTAssertEqual(LiveLinkFace.valueNames, try definition()["livelinkface_values"] as? [String])
        XCTAssertEqual(LiveLinkFace.valueNames.count, LiveLinkFace.valueCount)
    }
}
