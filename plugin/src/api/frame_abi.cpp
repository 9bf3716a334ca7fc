#include "api/frame_abi.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "stream/rotation.h"

namespace softdeca::api {
namespace {

void pose_out(const stream::Pose& p, softdeca_pose& out) {
  std::copy(p.position.begin(), p.position.end(), out.position);
  std::copy(p.rotation.begin(), p.rotation.end(), out.rotation);
}

stream::Pose pose_in(const softdeca_pose& in, const char* name) {
  stream::Pose p;
  std::copy(in.position, in.position + 3, p.position.begin());
  std::copy(in.rotation, in.rotation + 4, p.rotation.begin());
  require_finite(p.position.data(), 3, name);
  require_finite(p.rotation.data(), 4, name);
  if (!stream::normalize_rotation(p.rotation))
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, std::string(name) + ".rotation is not a unit quaternion");
  return p;
}

}  // namespace

void frame_to_abi(const stream::Frame& f, softdeca_frame* out) {
  reset_struct(out);
  out->flags = (f.has_head ? SOFTDECA_FRAME_HAS_HEAD : 0u) | (f.has_eyes ? SOFTDECA_FRAME_HAS_EYES : 0u) |
               (f.has_sequence ? SOFTDECA_FRAME_HAS_SEQUENCE : 0u);
  out->session_id = f.session_id;
  out->sequence = f.sequence;
  out->tracking = static_cast<int32_t>(f.tracking);
  out->profile_id = f.profile_id;
  out->capture_time = f.capture_time;
  out->send_time = f.send_time;
  out->receive_time = f.receive_time;
  std::copy(f.weights.begin(), f.weights.end(), out->weights);
  pose_out(f.head, out->head);
  pose_out(f.left_eye, out->left_eye);
  pose_out(f.right_eye, out->right_eye);
  out->landmark_count = f.landmark_count;
  std::copy(f.landmarks.begin(), f.landmarks.begin() + 3 * f.landmark_count, out->landmarks);
}

stream::Frame frame_from_abi(const softdeca_frame* in) {
  require_struct(in, "frame");
  stream::Frame f;
  require(in->tracking >= SOFTDECA_TRACKING_LOST && in->tracking <= SOFTDECA_TRACKING_LIMITED,
          "frame->tracking is not a softdeca_tracking");
  require((in->flags & ~7u) == 0, "frame->flags has unknown bits");
  require(in->landmark_count <= SOFTDECA_MAX_LANDMARKS, "frame->landmark_count exceeds 150");
  for (double t : {in->capture_time, in->send_time, in->receive_time})
    require(std::isfinite(t), "frame times must be finite", SOFTDECA_ERROR_NON_FINITE);
  require_finite(in->weights, SOFTDECA_BLENDSHAPE_COUNT, "frame->weights");
  for (std::size_t i = 0; i < SOFTDECA_BLENDSHAPE_COUNT; ++i)
    if (!(in->weights[i] >= 0 && in->weights[i] <= 1))
      throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, "frame->weights[" + std::to_string(i) + "] is outside [0, 1]");
  require_finite(in->landmarks, 3u * in->landmark_count, "frame->landmarks");
  f.has_head = in->flags & SOFTDECA_FRAME_HAS_HEAD;
  f.has_eyes = in->flags & SOFTDECA_FRAME_HAS_EYES;
  f.has_sequence = in->flags & SOFTDECA_FRAME_HAS_SEQUENCE;
  if (f.has_head) f.head = pose_in(in->head, "frame->head");
  if (f.has_eyes) {
    f.left_eye = pose_in(in->left_eye, "frame->left_eye");
    f.right_eye = pose_in(in->right_eye, "frame->right_eye");
  }
  f.session_id = in->session_id;
  f.sequence = in->sequence;
  f.tracking = static_cast<stream::Tracking>(in->tracking);
  f.profile_id = in->profile_id;
  f.capture_time = in->capture_time;
  f.send_time = in->send_time;
  f.receive_time = in->receive_time;
  std::copy(in->weights, in->weights + SOFTDECA_BLENDSHAPE_COUNT, f.weights.begin());
  f.landmark_count = static_cast<uint16_t>(in->landmark_count);
  std::copy(in->landmarks, in->landmarks + 3 * in->landmark_count, f.landmarks.begin());
  return f;
}

void profile_to_abi(const stream::wire::Profile* p, uint32_t* out_id, int32_t* out_indices,
                    uint32_t capacity, uint32_t* out_count) {
  require_not_null(out_id, "out_id");
  require_not_null(out_count, "out_count");
  const uint32_t n = p ? static_cast<uint32_t>(p->indices.size()) : 0;
  *out_count = n;
  require(capacity >= n, "the profile has " + std::to_string(n) + " indices, capacity is " + std::to_string(capacity),
          SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  if (n > 0) require_not_null(out_indices, "out_indices");
  *out_id = p ? p->id : 0;
  if (n > 0) std::copy(p->indices.begin(), p->indices.end(), out_indices);
}

void neutral_to_abi(const std::vector<float>& xyz, float* out_xyz, uint32_t vertex_capacity,
                    uint32_t* out_vertex_count) {
  require_not_null(out_vertex_count, "out_vertex_count");
  const uint32_t n = static_cast<uint32_t>(xyz.size() / 3);
  *out_vertex_count = n;
  require(vertex_capacity >= n, "the neutral mesh has " + std::to_string(n) + " vertices, capacity is " +
                                    std::to_string(vertex_capacity),
          SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  if (n > 0) {
    require_not_null(out_xyz, "out_xyz");
    std::copy(xyz.begin(), xyz.end(), out_xyz);
  }
}

recording::Header header_from_abi(const softdeca_recording_header* h) {
  require_struct(h, "header");
  for (double v : {h->start_unix_time, h->timecode_rate})
    require(std::isfinite(v) && v >= 0, "header times and rates must be finite and >= 0");
  recording::Header out;
  out.device = h->device ? h->device : "";
  out.subject = h->subject ? h->subject : "";
  out.source = h->source ? h->source : "";
  out.start_unix_time = h->start_unix_time;
  out.timecode_rate = h->timecode_rate;
  return out;
}

}  // namespace softdeca::api
