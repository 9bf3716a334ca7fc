// Conversions between the Euler angles of third-party formats and our quaternions (x, y, z, w).
// The conventions of those formats are not published; docs/protocol.md states the ones assumed.
#pragma once

#include <array>

namespace softdeca::stream {

using Quaternion = std::array<float, 4>;

// Yaw about +Y, pitch about +X, roll about +Z (radians), composed R = Ry(yaw) Rx(pitch) Rz(roll)
// in ARKit's right-handed face frame: Live Link Face's head and eye angles.
Quaternion quaternion_from_yaw_pitch_roll(double yaw, double pitch, double roll);
// Inverse of the above; pitch in [-pi/2, pi/2].
std::array<double, 3> yaw_pitch_roll_from_quaternion(const Quaternion& q);

// Unity Euler angles in degrees (Quaternion.Euler(x, y, z): z, then x, then y, in Unity's
// left-handed frame), mirrored into ARKit's right-handed frame (z negated): iFacialMocap.
Quaternion quaternion_from_unity_euler_degrees(double x, double y, double z);
std::array<double, 3> unity_euler_degrees_from_quaternion(const Quaternion& q);

// Unit length, or false when the quaternion is not finite or too far from unit length to be a
// rotation (|q| outside [0.9, 1.1]).
bool normalize_rotation(Quaternion& q);

}  // namespace softdeca::stream
