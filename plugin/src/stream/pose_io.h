// A pose as 7 little-endian floats (position xyz, quaternion xyzw): the same in datagrams and
// in recordings.
#pragma once

#include "stream/byte_io.h"
#include "stream/frame.h"

namespace softdeca::stream {

void write_pose(ByteWriter& w, const Pose& pose);

enum class PoseRead { ok, short_input, invalid };
// Reads a pose; `invalid` when a value is not finite, the position is beyond 1 km, or the
// quaternion is too far from unit length to be a rotation (it is renormalised otherwise).
PoseRead read_pose(ByteReader& r, Pose& pose);

}  // namespace softdeca::stream
