#include "stream/livelinkface_layout.h"

#include <algorithm>
#include <array>

#include "stream/arkit_names.h"
#include "stream/face_names_table.h"
#include "stream/rotation.h"

namespace softdeca::stream::livelinkface {
namespace {
constexpr std::array<const char*, kValueCount> kNames = SOFTDECA_LIVELINKFACE_VALUE_NAMES;
static_assert(SOFTDECA_LIVELINKFACE_VALUE_COUNT == kValueCount, "data/face_names.json: 61 Live Link Face values");

std::array<int, kValueCount> make_canonical() {
  std::array<int, kValueCount> m{};
  for (std::size_t i = 0; i < kValueCount; ++i) m[i] = blendshape_index(kNames[i], true);
  return m;
}
}  // namespace

const char* value_name(std::size_t i) { return i < kValueCount ? kNames[i] : nullptr; }

int canonical_index(std::size_t i) {
  static const std::array<int, kValueCount> kCanonical = make_canonical();
  return i < kValueCount ? kCanonical[i] : -1;
}

void values_to_frame(const Values& v, Frame& f) {
  for (std::size_t i = 0; i < kHeadYaw; ++i)
    f.weights[static_cast<std::size_t>(canonical_index(i))] = std::clamp(v[i], 0.0f, 1.0f);
  f.has_head = f.has_eyes = true;
  f.head = f.left_eye = f.right_eye = Pose{};
  f.head.rotation = quaternion_from_yaw_pitch_roll(v[kHeadYaw], v[kHeadYaw + 1], v[kHeadYaw + 2]);
  f.left_eye.rotation =
      quaternion_from_yaw_pitch_roll(v[kLeftEyeYaw], v[kLeftEyeYaw + 1], v[kLeftEyeYaw + 2]);
  f.right_eye.rotation =
      quaternion_from_yaw_pitch_roll(v[kRightEyeYaw], v[kRightEyeYaw + 1], v[kRightEyeYaw + 2]);
}

Values frame_to_values(const Frame& f) {
  Values v{};
  for (std::size_t i = 0; i < kHeadYaw; ++i)
    v[i] = f.weights[static_cast<std::size_t>(canonical_index(i))];
  const auto put = [&](std::size_t at, bool present, const Pose& p) {
    if (!present) return;
    const auto ypr = yaw_pitch_roll_from_quaternion(p.rotation);
    for (std::size_t k = 0; k < 3; ++k) v[at + k] = static_cast<float>(ypr[k]);
  };
  put(kHeadYaw, f.has_head, f.head);
  put(kLeftEyeYaw, f.has_eyes, f.left_eye);
  put(kRightEyeYaw, f.has_eyes, f.right_eye);
  return v;
}

}  // namespace softdeca::stream::livelinkface
