// A pose as 7 little-endian floats (position xyz, quaternion xyzw): the same in datagrams and
// in recordings.
#pragma once

#include "stream/byte_io.h"
#include "stream/frame.h"

namespace softdeca::stream {

void write_pose(ByteWriter& w, const Pose& pose);

// Whether a pose is one a tracker can report: every value finite, the position within 1 km,
// the quaternion near enough to unit length to be a rotation (it is then renormalised).
bool check_pose(Pose& pose);

enum class PoseRead { ok, short_input, invalid };
// Reads a pose; `invalid` when check_pose refuses it (the values read are kept as they were).
PoseRead read_pose(ByteReader& r, Pose& pose);

}  // namespace softdeca::stream
