// The 61 values of Epic's Live Link Face app, in its order (Unreal's EARFaceBlendShape): 52
// ARKit weights in an order of their own, then head yaw/pitch/roll and the left and right eyes'
// yaw/pitch/roll (radians). Names are ARKit's with a capital first letter, as in its CSV header.
#pragma once

#include <array>
#include <cstddef>

#include "stream/frame.h"

namespace softdeca::stream::livelinkface {

constexpr std::size_t kValueCount = 61;
constexpr std::size_t kHeadYaw = 52;      // then pitch, roll
constexpr std::size_t kLeftEyeYaw = 55;   // then pitch, roll
constexpr std::size_t kRightEyeYaw = 58;  // then pitch, roll

// Name of value i ("EyeBlinkLeft", ..., "RightEyeRoll"); nullptr when i >= 61.
const char* value_name(std::size_t i);
// Canonical blendshape index of value i, or -1 for the nine pose angles.
int canonical_index(std::size_t i);

using Values = std::array<float, kValueCount>;

// The canonical frame's weights (clamped to [0, 1]) and head and eye rotations (positions
// zero: Live Link Face has none) from the 61 values; has_head and has_eyes are set.
void values_to_frame(const Values& values, Frame& frame);
// The 61 values of a frame; absent poses give zero angles.
Values frame_to_values(const Frame& frame);

}  // namespace softdeca::stream::livelinkface
