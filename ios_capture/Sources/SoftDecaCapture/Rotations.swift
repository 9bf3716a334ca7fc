import Foundation

/// Euler angles of the third-party formats <-> quaternions (x, y, z, w); the conventions of
/// plugin/src/stream/rotation.cpp (docs/protocol.md states them). Computed in double precision
/// with the platform's libm, as the C++ and Python twins.
public enum Rotations {
    static func composeYXZ(yaw: Double, pitch: Double, roll: Double) -> (Double, Double, Double, Double) {
        let cy = cos(yaw / 2), sy = sin(yaw / 2)
        let cp = cos(pitch / 2), sp = sin(pitch / 2)
        let cr = cos(roll / 2), sr = sin(roll / 2)
        return (cy * sp * cr + sy * cp * sr,
                sy * cp * cr - cy * sp * sr,
                cy * cp * sr - sy * sp * cr,
                cy * cp * cr + sy * sp * sr)
    }

    static func decomposeYXZ(_ x: Double, _ y: Double, _ z: Double, _ w: Double) -> (yaw: Double, pitch: Double, roll: Double) {
        let r12 = 2 * (y * z - w * x)
        let pitch = asin(min(1.0, max(-1.0, -r12)))
        let yaw = atan2(2 * (x * z + w * y), 1 - 2 * (x * x + y * y))
        let roll = atan2(2 * (x * y + w * z), 1 - 2 * (x * x + z * z))
        return (yaw, pitch, roll)
    }

    /// Live Link Face: yaw about +Y, pitch about +X, roll about +Z (radians), R = Ry Rx Rz.
    public static func quaternion(yaw: Double, pitch: Double, roll: Double) -> SIMD4<Float> {
        let q = composeYXZ(yaw: yaw, pitch: pitch, roll: roll)
        return SIMD4(Float(q.0), Float(q.1), Float(q.2), Float(q.3))
    }

    public static func yawPitchRoll(_ q: SIMD4<Float>) -> (yaw: Double, pitch: Double, roll: Double) {
        decomposeYXZ(Double(q.x), Double(q.y), Double(q.z), Double(q.w))
    }

    /// iFacialMocap: Unity's `Quaternion.Euler(x, y, z)` in degrees, in Unity's left-handed frame,
    /// from a quaternion of ARKit's right-handed frame (mirrored: z negated).
    public static func unityEulerDegrees(_ q: SIMD4<Float>) -> (x: Double, y: Double, z: Double) {
        let e = decomposeYXZ(-Double(q.x), -Double(q.y), Double(q.z), Double(q.w))
        let deg = 180.0 / Double.pi
        return (e.pitch * deg, e.yaw * deg, e.roll * deg)
    }
}
