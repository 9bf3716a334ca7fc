// The one rule for the values of a frame read from a recording or a Live Link Face take, so
// that the reader, `softdeca info`, the player (C ABI and `play`), `replay` and `convert` all
// keep and count the same frames (docs/recording.md, "Values"):
//   refused: a time, weight, pose or landmark value that is not finite; a pose the wire
//            decoder would refuse (position beyond 1 km, a quaternion far from unit length,
//            such as all zeros); a landmark beyond 1 km.
//   clamped: weights outside [0, 1] become 0 or 1 (softdeca_frame documents [0, 1]).
// Rotations are renormalised. Live Link Face angles are radians within a full turn either way.
#pragma once

#include "stream/frame.h"

namespace softdeca::recording {

enum class FrameVerdict { ok, clamped, refused };

// Applies the rule to `frame` in place (clamping, renormalising) and says what it did.
FrameVerdict apply_frame_rule(stream::Frame& frame);

// A head or eye angle of a Live Link Face take (radians) that a tracker can report.
bool pose_angle_ok(float radians);

}  // namespace softdeca::recording
