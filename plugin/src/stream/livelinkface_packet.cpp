#include "stream/livelinkface_packet.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "stream/byte_io.h"
#include "stream/crc32.h"
#include "stream/livelinkface_layout.h"

namespace softdeca::stream::livelinkface {
namespace {

wire::Verdict drop(DropReason reason, const char* detail) { return {reason, detail}; }

// int32 length + UTF-8 text; false when the length lies.
bool read_name(ByteReader& r, std::string& out) {
  int32_t length = 0;
  if (!r.i32be(length) || length < 0 || static_cast<std::size_t>(length) > kMaxNameBytes) return false;
  return r.text(out, static_cast<std::size_t>(length));
}

}  // namespace

uint32_t session_id_of(const std::string& device_id, const std::string& subject) {
  const std::string key = device_id + '\n' + subject;
  return crc32(key.data(), key.size());
}

wire::Verdict decode_packet(const uint8_t* data, std::size_t size, Frame& f, PacketInfo& info) {
  if (size > kMaxPacketBytes) return drop(DropReason::oversized, "Live Link Face packet over 2048 bytes");
  ByteReader r(data, size);
  uint8_t version = 0;
  if (!r.u8(version)) return drop(DropReason::undersized, "empty datagram");
  if (version != kPacketVersion) return drop(DropReason::incompatible_version, "Live Link Face packet version is not 6");
  if (!read_name(r, info.device_id) || !read_name(r, info.subject))
    return drop(DropReason::bad_length, "Live Link Face name length disagrees with the packet");
  uint8_t count = 0;
  if (!r.i32be(info.frame_number) || !r.f32be(info.subframe) || !r.i32be(info.fps_numerator) ||
      !r.i32be(info.fps_denominator) || !r.u8(count))
    return drop(DropReason::undersized, "Live Link Face packet cut before its values");
  if (info.fps_numerator <= 0 || info.fps_denominator <= 0 || !std::isfinite(info.subframe))
    return drop(DropReason::bad_value, "Live Link Face frame rate or subframe invalid");
  // 61 values; 0 when the face is lost; a newer app's extra values are ignored.
  if (count != 0 && count < kValueCount) return drop(DropReason::bad_length, "Live Link Face packet with 1 to 60 values");
  if (r.remaining() < 4u * count) return drop(DropReason::bad_length, "Live Link Face packet shorter than its value count");
  Values values{};
  for (std::size_t i = 0; i < count; ++i) {
    float v = 0;
    r.f32be(v);
    if (!std::isfinite(v)) return drop(DropReason::bad_value, "Live Link Face value not finite");
    if (i < kValueCount) values[i] = v;
  }
  f = Frame{};
  f.session_id = session_id_of(info.device_id, info.subject);
  f.capture_time = (static_cast<double>(info.frame_number) + info.subframe) * info.fps_denominator /
                   info.fps_numerator;
  if (count == 0) {
    f.tracking = Tracking::lost;
  } else {
    values_to_frame(values, f);
  }
  return {};
}

void encode_packet(const Frame& f, const PacketInfo& info, std::vector<uint8_t>& out) {
  require(info.device_id.size() <= kMaxNameBytes && info.subject.size() <= kMaxNameBytes,
          "Live Link Face device id and subject have at most 255 bytes each");
  require(info.fps_numerator > 0 && info.fps_denominator > 0, "frame rate must be positive");
  require(std::isfinite(f.capture_time) && f.capture_time >= 0, "capture time must be finite and >= 0");
  const double frames = f.capture_time * info.fps_numerator / info.fps_denominator;
  require(frames < 2147483647.0, "capture time beyond Live Link Face's int32 frame number");
  const double whole = std::floor(frames);
  out.clear();
  ByteWriter w(out);
  w.u8(kPacketVersion);
  w.i32be(static_cast<int32_t>(info.device_id.size()));
  w.text(info.device_id);
  w.i32be(static_cast<int32_t>(info.subject.size()));
  w.text(info.subject);
  w.i32be(static_cast<int32_t>(whole));
  w.f32be(static_cast<float>(frames - whole));
  w.i32be(info.fps_numerator);
  w.i32be(info.fps_denominator);
  if (f.tracking == Tracking::lost) {
    w.u8(0);
    return;
  }
  const Values values = frame_to_values(f);
  for (float v : values) require(std::isfinite(v), "frame value not finite", SOFTDECA_ERROR_NON_FINITE);
  w.u8(static_cast<uint8_t>(kValueCount));
  for (float v : values) w.f32be(v);
}

}  // namespace softdeca::stream::livelinkface
