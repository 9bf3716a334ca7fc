// Encoders of our wire format (wire_format.h, docs/protocol.md).
#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "core/error.h"
#include "stream/byte_io.h"
#include "stream/crc32.h"
#include "stream/pose_io.h"
#include "stream/wire_format.h"

namespace softdeca::stream::wire {
namespace {

void header(ByteWriter& w, MessageType type, uint32_t session_id, uint32_t sequence) {
  for (uint8_t b : kMagic) w.u8(b);
  w.u8(kVersionMajor);
  w.u8(kVersionMinor);
  w.u8(static_cast<uint8_t>(type));
  w.u8(0);  // flags, reserved
  w.u32le(session_id);
  w.u32le(sequence);
}

void require_finite_values(const float* v, std::size_t n, const char* what) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) throw Error(SOFTDECA_ERROR_NON_FINITE, std::string(what) + " is not finite");
}

// Starts a block; returns where its length goes, patched by end_block.
std::size_t begin_block(ByteWriter& w, BlockType type) {
  w.u16le(static_cast<uint16_t>(type));
  const std::size_t at = w.size();
  w.u16le(0);
  return at;
}
void end_block(ByteWriter& w, std::size_t length_at) {
  w.patch_u16le(length_at, static_cast<uint16_t>(w.size() - length_at - 2));
}

void check_size(const std::vector<uint8_t>& out) {
  if (out.size() >= kDatagramLimit)
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT,
                "datagram of " + std::to_string(out.size()) + " bytes exceeds the 1,199-byte limit");
}

}  // namespace

uint32_t profile_id_of(const std::vector<uint16_t>& indices) {
  std::vector<uint8_t> bytes;
  ByteWriter w(bytes);
  for (uint16_t i : indices) w.u16le(i);
  return crc32(bytes.data(), bytes.size());
}

uint32_t neutral_id_of(const float* xyz, std::size_t vertex_count) {
  std::vector<uint8_t> bytes;
  ByteWriter w(bytes);
  for (std::size_t i = 0; i < vertex_count * 3; ++i) w.f32le(xyz[i]);
  return crc32(bytes.data(), bytes.size());
}

std::vector<NeutralChunk> split_neutral(const float* xyz, std::size_t vertex_count) {
  require(vertex_count >= 1 && vertex_count <= kMaxNeutralVertices,
          "a neutral mesh has 1 to " + std::to_string(kMaxNeutralVertices) + " vertices");
  require_finite_values(xyz, vertex_count * 3, "neutral vertex");
  const uint32_t id = neutral_id_of(xyz, vertex_count);
  std::vector<NeutralChunk> chunks;
  for (std::size_t first = 0; first < vertex_count; first += kNeutralChunkVertices) {
    const std::size_t n = std::min(kNeutralChunkVertices, vertex_count - first);
    NeutralChunk c;
    c.neutral_id = id;
    c.total_vertices = static_cast<uint16_t>(vertex_count);
    c.first_vertex = static_cast<uint16_t>(first);
    c.xyz.assign(xyz + 3 * first, xyz + 3 * (first + n));
    chunks.push_back(std::move(c));
  }
  return chunks;
}

void encode_frame(const Frame& f, std::vector<uint8_t>& out) {
  require(std::isfinite(f.capture_time) && std::isfinite(f.send_time),
          "frame times must be finite", SOFTDECA_ERROR_NON_FINITE);
  require(f.landmark_count <= kMaxLandmarks, "a frame carries at most 150 landmarks");
  require_finite_values(f.weights.data(), f.weights.size(), "weight");
  require_finite_values(f.landmarks.data(), 3u * f.landmark_count, "landmark");
  out.clear();
  ByteWriter w(out);
  header(w, MessageType::frame, f.session_id, f.sequence);
  w.f64le(f.capture_time);
  w.f64le(f.send_time);
  w.u8(static_cast<uint8_t>(f.tracking));
  w.u8(0);  // flags, reserved
  const std::size_t count_at = w.size();
  w.u16le(0);  // block count, patched below: a datagram cut at a block boundary is detected
  uint16_t blocks = 1;

  std::size_t at = begin_block(w, BlockType::weights);
  for (float v : f.weights)
    w.u16le(static_cast<uint16_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 65535.0)));
  end_block(w, at);
  if (f.has_head) {
    ++blocks;
    require_finite_values(f.head.position.data(), 3, "head position");
    require_finite_values(f.head.rotation.data(), 4, "head rotation");
    at = begin_block(w, BlockType::head_pose);
    write_pose(w, f.head);
    end_block(w, at);
  }
  if (f.has_eyes) {
    for (const Pose* p : {&f.left_eye, &f.right_eye}) {
      require_finite_values(p->position.data(), 3, "eye position");
      require_finite_values(p->rotation.data(), 4, "eye rotation");
    }
    ++blocks;
    at = begin_block(w, BlockType::eye_poses);
    write_pose(w, f.left_eye);
    write_pose(w, f.right_eye);
    end_block(w, at);
  }
  if (f.landmark_count > 0) {
    ++blocks;
    at = begin_block(w, BlockType::landmarks);
    w.u32le(f.profile_id);
    w.u16le(f.landmark_count);
    w.u16le(0);
    for (std::size_t i = 0; i < 3u * f.landmark_count; ++i) {
      const long q = std::lround(f.landmarks[i] / kLandmarkStep);
      if (q < -32768 || q > 32767)
        throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, "landmark coordinate " + std::to_string(f.landmarks[i]) +
                                                         " m is outside the [-0.32768, 0.32767] m the format carries");
      w.i16le(static_cast<int16_t>(q));
    }
    end_block(w, at);
  }
  w.patch_u16le(count_at, blocks);
  check_size(out);
}

void write_profile_body(ByteWriter& w, const Profile& p) {
  require(p.indices.size() <= kMaxLandmarks,
          "a profile names at most " + std::to_string(kMaxLandmarks) + " vertices");
  require(p.name.size() <= kMaxProfileName, "a profile name has at most 64 bytes");
  for (uint16_t i : p.indices)
    require(i < kArkitVertexCount, "profile vertex " + std::to_string(i) + " is not below 1220");
  require(std::set<uint16_t>(p.indices.begin(), p.indices.end()).size() == p.indices.size(),
          "a profile names each vertex once");
  require(p.id == profile_id_of(p.indices), "profile id does not match its indices");
  w.u32le(p.id);
  w.u16le(static_cast<uint16_t>(p.indices.size()));
  w.u8(static_cast<uint8_t>(p.name.size()));
  w.u8(0);
  w.text(p.name);
  for (uint16_t i : p.indices) w.u16le(i);
}

void encode_profile(uint32_t session_id, uint32_t sequence, const Profile& p,
                    std::vector<uint8_t>& out) {
  out.clear();
  ByteWriter w(out);
  header(w, MessageType::profile, session_id, sequence);
  write_profile_body(w, p);
  check_size(out);
}

void encode_neutral_chunk(uint32_t session_id, uint32_t sequence, const NeutralChunk& c,
                          std::vector<uint8_t>& out) {
  const std::size_t n = c.xyz.size() / 3;
  require(c.xyz.size() % 3 == 0 && n >= 1 && n <= kNeutralChunkVertices,
          "a neutral chunk holds 1 to 80 vertices");
  require(c.total_vertices >= 1 && c.total_vertices <= kMaxNeutralVertices &&
              c.first_vertex + n <= c.total_vertices,
          "neutral chunk outside its mesh");
  require_finite_values(c.xyz.data(), c.xyz.size(), "neutral vertex");
  out.clear();
  ByteWriter w(out);
  header(w, MessageType::neutral_chunk, session_id, sequence);
  w.u32le(c.neutral_id);
  w.u16le(c.total_vertices);
  w.u16le(c.first_vertex);
  w.u16le(static_cast<uint16_t>(n));
  w.u16le(0);
  for (float v : c.xyz) w.f32le(v);
  check_size(out);
}

void encode_request(uint32_t session_id, uint32_t sequence, const Request& r,
                    std::vector<uint8_t>& out) {
  out.clear();
  ByteWriter w(out);
  header(w, MessageType::request, session_id, sequence);
  w.u8(static_cast<uint8_t>(r.what));
  w.u8(0);
  w.u16le(0);
  w.u32le(r.id);
}

}  // namespace softdeca::stream::wire
