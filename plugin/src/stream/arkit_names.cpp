#include "stream/arkit_names.h"

#include <array>
#include <cctype>

namespace softdeca::stream {
namespace {
constexpr std::array<const char*, kBlendshapeCount> kNames = {
    "browDownLeft",       "browDownRight",     "browInnerUp",       "browOuterUpLeft",
    "browOuterUpRight",   "cheekPuff",         "cheekSquintLeft",   "cheekSquintRight",
    "eyeBlinkLeft",       "eyeBlinkRight",     "eyeLookDownLeft",   "eyeLookDownRight",
    "eyeLookInLeft",      "eyeLookInRight",    "eyeLookOutLeft",    "eyeLookOutRight",
    "eyeLookUpLeft",      "eyeLookUpRight",    "eyeSquintLeft",     "eyeSquintRight",
    "eyeWideLeft",        "eyeWideRight",      "jawForward",        "jawLeft",
    "jawOpen",            "jawRight",          "mouthClose",        "mouthDimpleLeft",
    "mouthDimpleRight",   "mouthFrownLeft",    "mouthFrownRight",   "mouthFunnel",
    "mouthLeft",          "mouthLowerDownLeft", "mouthLowerDownRight", "mouthPressLeft",
    "mouthPressRight",    "mouthPucker",       "mouthRight",        "mouthRollLower",
    "mouthRollUpper",     "mouthShrugLower",   "mouthShrugUpper",   "mouthSmileLeft",
    "mouthSmileRight",    "mouthStretchLeft",  "mouthStretchRight", "mouthUpperUpLeft",
    "mouthUpperUpRight",  "noseSneerLeft",     "noseSneerRight",    "tongueOut",
};

bool same(std::string_view canonical, std::string_view name, bool ignore_first_case) {
  if (canonical.size() != name.size() || name.empty()) return false;
  const bool first_ok =
      canonical[0] == name[0] ||
      (ignore_first_case && std::tolower(static_cast<unsigned char>(name[0])) == canonical[0]);
  return first_ok && canonical.substr(1) == name.substr(1);
}
}  // namespace

const char* blendshape_name(std::size_t index) {
  return index < kNames.size() ? kNames[index] : nullptr;
}

int blendshape_index(std::string_view name, bool ignore_first_case) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (same(kNames[i], name, ignore_first_case)) return static_cast<int>(i);
  return -1;
}

}  // namespace softdeca::stream
