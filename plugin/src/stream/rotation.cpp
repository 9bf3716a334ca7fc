#include "stream/rotation.h"

#include <algorithm>
#include <cmath>

namespace softdeca::stream {
namespace {
constexpr double kDegree = 3.14159265358979323846 / 180.0;

// q = qy(yaw) * qx(pitch) * qz(roll) in double, as (x, y, z, w).
std::array<double, 4> compose_yxz(double yaw, double pitch, double roll) {
  const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
  const double cp = std::cos(pitch / 2), sp = std::sin(pitch / 2);
  const double cr = std::cos(roll / 2), sr = std::sin(roll / 2);
  return {cy * sp * cr + sy * cp * sr, sy * cp * cr - cy * sp * sr,
          cy * cp * sr - sy * sp * cr, cy * cp * cr + sy * sp * sr};
}

// Inverse of compose_yxz: R = Ry Rx Rz has R[1][2] = -sin(pitch).
std::array<double, 3> decompose_yxz(double x, double y, double z, double w) {
  const double r12 = 2 * (y * z - w * x);
  const double pitch = std::asin(std::clamp(-r12, -1.0, 1.0));
  const double r02 = 2 * (x * z + w * y), r22 = 1 - 2 * (x * x + y * y);
  const double r10 = 2 * (x * y + w * z), r11 = 1 - 2 * (x * x + z * z);
  return {std::atan2(r02, r22), pitch, std::atan2(r10, r11)};
}

Quaternion to_float(const std::array<double, 4>& q) {
  return {static_cast<float>(q[0]), static_cast<float>(q[1]), static_cast<float>(q[2]),
          static_cast<float>(q[3])};
}
}  // namespace

Quaternion quaternion_from_yaw_pitch_roll(double yaw, double pitch, double roll) {
  return to_float(compose_yxz(yaw, pitch, roll));
}

std::array<double, 3> yaw_pitch_roll_from_quaternion(const Quaternion& q) {
  return decompose_yxz(q[0], q[1], q[2], q[3]);
}

Quaternion quaternion_from_unity_euler_degrees(double x, double y, double z) {
  // Unity composes qy * qx * qz: the same order as yaw/pitch/roll. Mirroring z across the
  // handedness change keeps the z component and negates x and y.
  const auto q = compose_yxz(y * kDegree, x * kDegree, z * kDegree);
  return to_float({-q[0], -q[1], q[2], q[3]});
}

std::array<double, 3> unity_euler_degrees_from_quaternion(const Quaternion& q) {
  const auto ypr = decompose_yxz(-q[0], -q[1], q[2], q[3]);
  return {ypr[1] / kDegree, ypr[0] / kDegree, ypr[2] / kDegree};
}

bool normalize_rotation(Quaternion& q) {
  double n2 = 0;
  for (float c : q) {
    if (!std::isfinite(c)) return false;
    n2 += double(c) * c;
  }
  const double n = std::sqrt(n2);
  if (n < 0.9 || n > 1.1) return false;
  for (float& c : q) c = static_cast<float>(c / n);
  return true;
}

}  // namespace softdeca::stream
