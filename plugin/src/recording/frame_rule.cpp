#include "recording/frame_rule.h"

#include <cmath>

#include "stream/pose_io.h"

namespace softdeca::recording {
namespace {
constexpr float kMaxLandmarkMetres = 1e3f;  // as a pose's position (stream/pose_io.h)
constexpr double kFullTurn = 6.283185307179586;
}  // namespace

FrameVerdict apply_frame_rule(stream::Frame& f) {
  for (double t : {f.capture_time, f.send_time, f.receive_time})
    if (!std::isfinite(t)) return FrameVerdict::refused;
  for (float w : f.weights)
    if (!std::isfinite(w)) return FrameVerdict::refused;
  if (f.has_head && !stream::check_pose(f.head)) return FrameVerdict::refused;
  if (f.has_eyes && (!stream::check_pose(f.left_eye) || !stream::check_pose(f.right_eye))) return FrameVerdict::refused;
  if (f.landmark_count > stream::kMaxLandmarks) return FrameVerdict::refused;
  for (std::size_t i = 0; i < 3u * f.landmark_count; ++i)
    if (!std::isfinite(f.landmarks[i]) || std::fabs(f.landmarks[i]) > kMaxLandmarkMetres) return FrameVerdict::refused;
  bool clamped = false;
  for (float& w : f.weights) {
    if (w >= 0 && w <= 1) continue;
    w = w < 0 ? 0.0f : 1.0f;
    clamped = true;
  }
  return clamped ? FrameVerdict::clamped : FrameVerdict::ok;
}

bool pose_angle_ok(float radians) { return std::isfinite(radians) && std::fabs(radians) <= kFullTurn; }

}  // namespace softdeca::recording
