// A frame between two recorded frames, for playback at any time.
#pragma once

#include "stream/frame.h"

namespace softdeca::recording {

// The frame at fraction t in [0, 1] from a to b: weights, positions and landmarks linearly,
// rotations by spherical interpolation, times linearly. Where the two cannot be blended
// (tracking lost in one, a pose or the landmark profile only in one) the nearer frame is used.
stream::Frame interpolate(const stream::Frame& a, const stream::Frame& b, double t);

}  // namespace softdeca::recording
