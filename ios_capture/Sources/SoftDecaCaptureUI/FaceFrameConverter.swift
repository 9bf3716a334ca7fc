#if canImport(ARKit)
import ARKit
import Foundation
import SoftDecaCapture

/// `ARFrame` + `ARFaceAnchor` -> `CaptureFrame`: blend shapes by name, the anchor and eye
/// transforms, the face mesh, the landmarks of the stream's profile, the timecode of the moment
/// of capture.
public enum FaceFrameConverter {
    public static func frame(from arFrame: ARFrame, anchor: ARFaceAnchor, profile: LandmarkProfile?,
                             timecodeRate: Int, withMesh: Bool) throws -> CaptureFrame {
        var weights = [String: Float]()
        for (location, value) in anchor.blendShapes { weights[location.rawValue] = value.floatValue }
        // ARFrame.timestamp counts on the system uptime clock: the wall-clock moment of capture.
        let captured = Date(timeIntervalSinceNow: arFrame.timestamp - ProcessInfo.processInfo.systemUptime)
        let tracking: TrackingState
        if !anchor.isTracked {
            tracking = .lost
        } else if case .normal = arFrame.camera.trackingState {
            tracking = .tracked
        } else {
            tracking = .limited
        }
        var f = try CaptureFrame(timestamp: arFrame.timestamp, timecode: Timecode(date: captured, rate: timecodeRate),
                                 tracking: tracking, weightsByName: weights)
        f.head = try Pose(columnMajor: flatten(anchor.transform))
        f.eyes = (try Pose(columnMajor: flatten(anchor.leftEyeTransform)), try Pose(columnMajor: flatten(anchor.rightEyeTransform)))
        if withMesh || profile != nil {
            f.meshVertices = anchor.geometry.vertices.map { SIMD3<Float>($0.x, $0.y, $0.z) }
            if let p = profile { try f.selectLandmarks(p) }
            if !withMesh { f.meshVertices = nil }
        }
        return f
    }

    static func flatten(_ m: simd_float4x4) -> [Float] {
        [m.columns.0, m.columns.1, m.columns.2, m.columns.3].flatMap { [$0.x, $0.y, $0.z, $0.w] }
    }
}
#endif
