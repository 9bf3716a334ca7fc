// Decoder of our wire format (wire_format.h, docs/protocol.md). Every field is read through
// ByteReader, and every length and count is checked against the bytes actually present.
#include <cmath>
#include <cstring>
#include <set>

#include "stream/byte_io.h"
#include "stream/crc32.h"
#include "stream/pose_io.h"
#include "stream/wire_format.h"

namespace softdeca::stream::wire {
namespace {

constexpr std::size_t kFrameFixedBytes = 20;  // capture, send, tracking, flags, block count

Verdict drop(DropReason reason, const char* detail) { return {reason, detail}; }

Verdict pose_verdict(PoseRead read) {
  switch (read) {
    case PoseRead::ok: return {};
    case PoseRead::short_input: return drop(DropReason::bad_length, "pose block too short");
    case PoseRead::invalid: break;
  }
  return drop(DropReason::bad_value, "pose not finite or not a rotation");
}

Verdict decode_blocks(ByteReader& r, uint16_t block_count, Frame& f) {
  unsigned seen = 0;
  std::size_t blocks = 0;
  while (r.remaining() > 0) {
    ++blocks;
    uint16_t type = 0, length = 0;
    if (!r.u16le(type) || !r.u16le(length)) return drop(DropReason::bad_length, "truncated block header");
    if (length > r.remaining()) return drop(DropReason::bad_length, "block runs past the datagram");
    // Extra bytes at the end of a block belong to a newer minor version and are skipped.
    ByteReader b = r.sub(length);
    if (type >= 1 && type <= 4) {
      const unsigned bit = 1u << type;
      if (seen & bit) return drop(DropReason::bad_value, "duplicate block");
      seen |= bit;
    }
    switch (static_cast<BlockType>(type)) {
      case BlockType::weights:
        for (float& w : f.weights) {
          uint16_t q = 0;
          if (!b.u16le(q)) return drop(DropReason::bad_length, "weights block too short");
          w = static_cast<float>(q / 65535.0);
        }
        break;
      case BlockType::head_pose:
        if (const Verdict v = pose_verdict(read_pose(b, f.head)); v.reason != DropReason::none) return v;
        f.has_head = true;
        break;
      case BlockType::eye_poses:
        for (Pose* eye : {&f.left_eye, &f.right_eye})
          if (const Verdict v = pose_verdict(read_pose(b, *eye)); v.reason != DropReason::none) return v;
        f.has_eyes = true;
        break;
      case BlockType::landmarks: {
        uint16_t count = 0, reserved = 0;
        if (!b.u32le(f.profile_id) || !b.u16le(count) || !b.u16le(reserved))
          return drop(DropReason::bad_length, "landmark block too short");
        if (count > kMaxLandmarks) return drop(DropReason::bad_value, "more landmarks than 150");
        if (b.remaining() < 6u * count) return drop(DropReason::bad_length, "landmark block too short");
        for (std::size_t i = 0; i < 3u * count; ++i) {
          int16_t q = 0;
          b.i16le(q);
          f.landmarks[i] = static_cast<float>(q * kLandmarkStep);
        }
        f.landmark_count = count;
        break;
      }
      default:
        break;  // a block of a newer minor version: skipped
    }
  }
  if (blocks != block_count) return drop(DropReason::bad_length, "block count disagrees with the blocks");
  if (!(seen & (1u << static_cast<unsigned>(BlockType::weights))))
    return drop(DropReason::bad_length, "frame without a weights block");
  return {};
}

Verdict decode_frame(ByteReader& r, Frame& f) {
  if (r.remaining() < kFrameFixedBytes) return drop(DropReason::undersized, "frame shorter than 36 bytes");
  uint8_t tracking = 0, flags = 0;
  uint16_t block_count = 0;
  r.f64le(f.capture_time);
  r.f64le(f.send_time);
  r.u8(tracking);
  r.u8(flags);
  r.u16le(block_count);
  if (!std::isfinite(f.capture_time) || !std::isfinite(f.send_time))
    return drop(DropReason::bad_value, "frame time not finite");
  if (tracking > static_cast<uint8_t>(Tracking::limited))
    return drop(DropReason::bad_value, "unknown tracking state");
  f.tracking = static_cast<Tracking>(tracking);
  return decode_blocks(r, block_count, f);
}

}  // namespace

Verdict read_profile_body(ByteReader& r, Profile& p) {
  uint16_t count = 0;
  uint8_t name_length = 0, reserved = 0;
  if (!r.u32le(p.id) || !r.u16le(count) || !r.u8(name_length) || !r.u8(reserved))
    return drop(DropReason::undersized, "profile shorter than 24 bytes");
  if (count > kMaxLandmarks) return drop(DropReason::bad_value, "profile with more than 150 vertices");
  if (name_length > kMaxProfileName) return drop(DropReason::bad_value, "profile name over 64 bytes");
  if (!r.text(p.name, name_length) || r.remaining() < 2u * count)
    return drop(DropReason::bad_length, "profile shorter than its counts");
  p.indices.resize(count);
  std::set<uint16_t> unique;
  for (uint16_t& i : p.indices) {
    r.u16le(i);
    if (i >= kArkitVertexCount) return drop(DropReason::bad_value, "profile vertex index not below 1220");
    if (!unique.insert(i).second) return drop(DropReason::bad_value, "profile names a vertex twice");
  }
  if (profile_id_of(p.indices) != p.id) return drop(DropReason::bad_value, "profile id does not match its indices");
  return {};
}

namespace {

Verdict decode_neutral(ByteReader& r, NeutralChunk& c) {
  uint16_t count = 0, reserved = 0;
  if (!r.u32le(c.neutral_id) || !r.u16le(c.total_vertices) || !r.u16le(c.first_vertex) ||
      !r.u16le(count) || !r.u16le(reserved))
    return drop(DropReason::undersized, "neutral chunk shorter than 28 bytes");
  if (c.total_vertices == 0 || c.total_vertices > kMaxNeutralVertices || count == 0 ||
      count > kNeutralChunkVertices || c.first_vertex + count > c.total_vertices)
    return drop(DropReason::bad_value, "neutral chunk counts out of range");
  if (r.remaining() < 12u * count) return drop(DropReason::bad_length, "neutral chunk shorter than its count");
  c.xyz.resize(3u * count);
  for (float& v : c.xyz) {
    r.f32le(v);
    if (!std::isfinite(v)) return drop(DropReason::bad_value, "neutral vertex not finite");
  }
  return {};
}

Verdict decode_request(ByteReader& r, Request& q) {
  uint8_t what = 0, reserved8 = 0;
  uint16_t reserved16 = 0;
  if (!r.u8(what) || !r.u8(reserved8) || !r.u16le(reserved16) || !r.u32le(q.id))
    return drop(DropReason::undersized, "request shorter than 24 bytes");
  if (what != static_cast<uint8_t>(RequestKind::profile) && what != static_cast<uint8_t>(RequestKind::neutral))
    return drop(DropReason::unknown_type, "request for something this version does not know");
  q.what = static_cast<RequestKind>(what);
  return {};
}

}  // namespace

Verdict decode(const uint8_t* data, std::size_t size, Message& out) {
  if (size >= kDatagramLimit) return drop(DropReason::oversized, "datagram of 1,200 bytes or more");
  if (size < kHeaderBytes) return drop(DropReason::undersized, "datagram shorter than the 16-byte header");
  if (std::memcmp(data, kMagic.data(), kMagic.size()) != 0) return drop(DropReason::bad_magic, "no SDCA magic");
  ByteReader r(data + kMagic.size(), size - kMagic.size());
  uint8_t major = 0, type = 0, flags = 0;
  r.u8(major);
  r.u8(out.envelope.minor);
  r.u8(type);
  r.u8(flags);
  r.u32le(out.envelope.session_id);
  r.u32le(out.envelope.sequence);
  if (major != kVersionMajor) return drop(DropReason::incompatible_version, "protocol major version is not 1");
  out.envelope.type = static_cast<MessageType>(type);
  switch (out.envelope.type) {
    case MessageType::frame: {
      out.frame = Frame{};
      out.frame.session_id = out.envelope.session_id;
      out.frame.sequence = out.envelope.sequence;
      out.frame.has_sequence = true;
      return decode_frame(r, out.frame);
    }
    case MessageType::profile: out.profile = Profile{}; return read_profile_body(r, out.profile);
    case MessageType::neutral_chunk: out.neutral = NeutralChunk{}; return decode_neutral(r, out.neutral);
    case MessageType::request: return decode_request(r, out.request);
  }
  return drop(DropReason::unknown_type, "message type of a newer minor version");
}

}  // namespace softdeca::stream::wire
