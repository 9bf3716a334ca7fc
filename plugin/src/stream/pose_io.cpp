#include "stream/pose_io.h"

#include <algorithm>
#include <cmath>

#include "stream/rotation.h"

namespace softdeca::stream {

void write_pose(ByteWriter& w, const Pose& p) {
  for (float v : p.position) w.f32le(v);
  for (float v : p.rotation) w.f32le(v);
}

PoseRead read_pose(ByteReader& r, Pose& p) {
  float v[7];
  for (float& x : v)
    if (!r.f32le(x)) return PoseRead::short_input;
  std::copy(v, v + 3, p.position.begin());
  std::copy(v + 3, v + 7, p.rotation.begin());
  return check_pose(p) ? PoseRead::ok : PoseRead::invalid;
}

bool check_pose(Pose& p) {
  for (float x : p.position)
    if (!std::isfinite(x) || std::fabs(x) > 1e3f) return false;
  return normalize_rotation(p.rotation);
}

}  // namespace softdeca::stream
