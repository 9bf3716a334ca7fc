#include "recording/record_codec.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "stream/arkit_names.h"
#include "stream/pose_io.h"

namespace softdeca::recording {
namespace {
using stream::ByteReader;
using stream::ByteWriter;
using stream::Frame;

constexpr uint8_t kHasHead = 1, kHasEyes = 2, kHasSequence = 4;

void field(ByteWriter& w, HeaderTag tag, const std::vector<uint8_t>& body) {
  w.u16le(static_cast<uint16_t>(tag));
  w.u32le(static_cast<uint32_t>(body.size()));
  w.bytes(body.data(), body.size());
}
void text_field(ByteWriter& w, HeaderTag tag, const std::string& text) {
  field(w, tag, std::vector<uint8_t>(text.begin(), text.end()));
}
void f64_field(ByteWriter& w, HeaderTag tag, double v) {
  std::vector<uint8_t> body;
  ByteWriter(body).f64le(v);
  field(w, tag, body);
}

std::string canonical_names() {
  std::string names;
  for (std::size_t i = 0; i < stream::kBlendshapeCount; ++i)
    names += (i ? "," : "") + std::string(stream::blendshape_name(i));
  return names;
}

}  // namespace

void encode_header_fields(const Header& h, std::vector<uint8_t>& out) {
  ByteWriter w(out);
  text_field(w, HeaderTag::device, h.device);
  text_field(w, HeaderTag::subject, h.subject);
  text_field(w, HeaderTag::source, h.source);
  f64_field(w, HeaderTag::start_unix_time, h.start_unix_time);
  f64_field(w, HeaderTag::timecode_rate, h.timecode_rate);
  text_field(w, HeaderTag::clock, h.clock);
  text_field(w, HeaderTag::units, h.units);
  text_field(w, HeaderTag::coordinate_frame, h.coordinate_frame);
  text_field(w, HeaderTag::blendshape_names, canonical_names());
  if (h.has_profile) {
    std::vector<uint8_t> body;
    ByteWriter b(body);
    stream::wire::write_profile_body(b, h.profile);
    field(w, HeaderTag::profile, body);
  }
  if (!h.neutral.empty()) {
    std::vector<uint8_t> body;
    encode_neutral_record(h.neutral, body);
    body.erase(body.begin());  // the record type byte: a header field is the body alone
    field(w, HeaderTag::neutral, body);
  }
}

bool decode_header_fields(ByteReader& r, Header& h, std::vector<int>& weight_order) {
  weight_order.clear();
  bool has_names = false;
  while (r.remaining() > 0) {
    uint16_t tag = 0;
    uint32_t length = 0;
    if (!r.u16le(tag) || !r.u32le(length) || length > r.remaining()) return false;
    ByteReader b = r.sub(length);
    std::string text;
    switch (static_cast<HeaderTag>(tag)) {
      case HeaderTag::device: b.text(h.device, length); break;
      case HeaderTag::subject: b.text(h.subject, length); break;
      case HeaderTag::source: b.text(h.source, length); break;
      case HeaderTag::clock: b.text(h.clock, length); break;
      case HeaderTag::units: b.text(h.units, length); break;
      case HeaderTag::coordinate_frame: b.text(h.coordinate_frame, length); break;
      case HeaderTag::start_unix_time:
        if (!b.f64le(h.start_unix_time) || !std::isfinite(h.start_unix_time)) return false;
        break;
      case HeaderTag::timecode_rate:
        if (!b.f64le(h.timecode_rate) || !std::isfinite(h.timecode_rate) || h.timecode_rate < 0) return false;
        break;
      case HeaderTag::blendshape_names: {
        b.text(text, length);
        std::size_t begin = 0;
        while (begin <= text.size() && weight_order.size() < 1024) {
          std::size_t end = text.find(',', begin);
          if (end == std::string::npos) end = text.size();
          weight_order.push_back(stream::blendshape_index(std::string_view(text).substr(begin, end - begin)));
          begin = end + 1;
        }
        has_names = true;
        break;
      }
      case HeaderTag::profile:
        if (stream::wire::read_profile_body(b, h.profile).reason != stream::DropReason::none) return false;
        h.has_profile = true;
        break;
      case HeaderTag::neutral:
        if (!decode_neutral_body(b, h.neutral)) return false;
        break;
      default:
        break;  // a tag of a newer minor version
    }
  }
  return has_names;
}

void encode_frame_record(const Frame& f, std::vector<uint8_t>& out) {
  require(f.landmark_count <= stream::kMaxLandmarks, "too many landmarks");
  out.clear();
  ByteWriter w(out);
  w.u8(static_cast<uint8_t>(RecordType::frame));
  w.u8(static_cast<uint8_t>(f.tracking));
  w.u8(static_cast<uint8_t>((f.has_head ? kHasHead : 0) | (f.has_eyes ? kHasEyes : 0) |
                            (f.has_sequence ? kHasSequence : 0)));
  w.u8(0);
  w.u32le(f.session_id);
  w.u32le(f.sequence);
  w.u32le(f.profile_id);
  w.f64le(f.capture_time);
  w.f64le(f.send_time);
  w.f64le(f.receive_time);
  w.u16le(static_cast<uint16_t>(f.weights.size()));
  w.u16le(f.landmark_count);
  for (float v : f.weights) w.f32le(v);
  if (f.has_head) stream::write_pose(w, f.head);
  if (f.has_eyes) {
    stream::write_pose(w, f.left_eye);
    stream::write_pose(w, f.right_eye);
  }
  for (std::size_t i = 0; i < 3u * f.landmark_count; ++i) w.f32le(f.landmarks[i]);
}

bool decode_frame_record(ByteReader& r, const std::vector<int>& weight_order, Frame& f) {
  f = Frame{};
  uint8_t tracking = 0, flags = 0, reserved = 0;
  uint16_t weight_count = 0, landmark_count = 0;
  if (!r.u8(tracking) || !r.u8(flags) || !r.u8(reserved) || !r.u32le(f.session_id) ||
      !r.u32le(f.sequence) || !r.u32le(f.profile_id) || !r.f64le(f.capture_time) ||
      !r.f64le(f.send_time) || !r.f64le(f.receive_time) || !r.u16le(weight_count) ||
      !r.u16le(landmark_count))
    return false;
  if (tracking > static_cast<uint8_t>(stream::Tracking::limited) || weight_count != weight_order.size() ||
      landmark_count > stream::kMaxLandmarks)
    return false;
  f.tracking = static_cast<stream::Tracking>(tracking);
  f.has_sequence = flags & kHasSequence;
  // Values are taken as written; whether they are usable is the frame rule's (frame_rule.h).
  for (std::size_t i = 0; i < weight_count; ++i) {
    float v = 0;
    if (!r.f32le(v)) return false;
    if (weight_order[i] >= 0) f.weights[static_cast<std::size_t>(weight_order[i])] = v;
  }
  f.has_head = flags & kHasHead;
  f.has_eyes = flags & kHasEyes;
  using stream::PoseRead;
  if (f.has_head && stream::read_pose(r, f.head) == PoseRead::short_input) return false;
  if (f.has_eyes && (stream::read_pose(r, f.left_eye) == PoseRead::short_input ||
                     stream::read_pose(r, f.right_eye) == PoseRead::short_input))
    return false;
  for (std::size_t i = 0; i < 3u * landmark_count; ++i)
    if (!r.f32le(f.landmarks[i])) return false;
  f.landmark_count = landmark_count;
  return true;  // bytes after this belong to a newer minor version
}

void encode_profile_record(const stream::wire::Profile& p, std::vector<uint8_t>& out) {
  out.clear();
  ByteWriter w(out);
  w.u8(static_cast<uint8_t>(RecordType::profile));
  stream::wire::write_profile_body(w, p);
}

void encode_neutral_record(const std::vector<float>& xyz, std::vector<uint8_t>& out) {
  const std::size_t n = xyz.size() / 3;
  require(xyz.size() % 3 == 0 && n >= 1 && n <= stream::wire::kMaxNeutralVertices,
          "a neutral mesh has 1 to 4096 vertices");
  out.clear();
  ByteWriter w(out);
  w.u8(static_cast<uint8_t>(RecordType::neutral));
  w.u32le(static_cast<uint32_t>(n));
  for (float v : xyz) w.f32le(v);
}

bool decode_neutral_body(ByteReader& r, std::vector<float>& xyz) {
  uint32_t n = 0;
  if (!r.u32le(n) || n == 0 || n > stream::wire::kMaxNeutralVertices || r.remaining() < 12u * n) return false;
  xyz.resize(3u * n);
  for (float& v : xyz)
    if (!r.f32le(v) || !std::isfinite(v)) return false;
  return true;
}

}  // namespace softdeca::recording
