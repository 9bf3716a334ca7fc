#include "recording/frame_interpolation.h"

#include <cmath>

#include "stream/rotation.h"

namespace softdeca::recording {
namespace {
using stream::Frame;
using stream::Pose;

float lerp(float a, float b, double t) { return static_cast<float>(a + (double(b) - a) * t); }

stream::Quaternion slerp(const stream::Quaternion& a, stream::Quaternion b, double t) {
  double dot = 0;
  for (int i = 0; i < 4; ++i) dot += double(a[i]) * b[i];
  if (dot < 0) {  // the shorter way round
    for (float& c : b) c = -c;
    dot = -dot;
  }
  double wa = 1 - t, wb = t;
  if (dot < 0.9995) {
    const double theta = std::acos(dot);
    wa = std::sin((1 - t) * theta) / std::sin(theta);
    wb = std::sin(t * theta) / std::sin(theta);
  }
  stream::Quaternion q{};
  double n2 = 0;
  for (int i = 0; i < 4; ++i) {
    q[i] = static_cast<float>(wa * a[i] + wb * b[i]);
    n2 += double(q[i]) * q[i];
  }
  for (float& c : q) c = static_cast<float>(c / std::sqrt(n2));
  return q;
}

Pose blend(const Pose& a, const Pose& b, double t) {
  Pose p;
  for (int i = 0; i < 3; ++i) p.position[i] = lerp(a.position[i], b.position[i], t);
  p.rotation = slerp(a.rotation, b.rotation, t);
  return p;
}
}  // namespace

Frame interpolate(const Frame& a, const Frame& b, double t) {
  const Frame& nearer = t < 0.5 ? a : b;
  if (a.tracking != stream::Tracking::tracked || b.tracking != stream::Tracking::tracked) return nearer;
  Frame f = nearer;
  f.capture_time = a.capture_time + (b.capture_time - a.capture_time) * t;
  f.send_time = a.send_time + (b.send_time - a.send_time) * t;
  f.receive_time = a.receive_time + (b.receive_time - a.receive_time) * t;
  for (std::size_t i = 0; i < f.weights.size(); ++i) f.weights[i] = lerp(a.weights[i], b.weights[i], t);
  if (a.has_head && b.has_head) f.head = blend(a.head, b.head, t);
  if (a.has_eyes && b.has_eyes) {
    f.left_eye = blend(a.left_eye, b.left_eye, t);
    f.right_eye = blend(a.right_eye, b.right_eye, t);
  }
  if (a.profile_id == b.profile_id && a.landmark_count == b.landmark_count)
    for (std::size_t i = 0; i < 3u * a.landmark_count; ++i)
      f.landmarks[i] = lerp(a.landmarks[i], b.landmarks[i], t);
  return f;
}

}  // namespace softdeca::recording
