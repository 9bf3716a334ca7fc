// Our UDP wire format, version 1.0 (docs/protocol.md is its specification): little-endian
// datagrams under 1,200 bytes, a 16-byte header, then one message. The codec here is the only
// C++ implementation; the Python one in training/softdeca_train/streaming/protocol.py must
// produce the same bytes (the golden packets in tests/golden/streaming check both).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "stream/byte_io.h"
#include "stream/drop_reason.h"
#include "stream/frame.h"

namespace softdeca::stream::wire {

constexpr std::array<uint8_t, 4> kMagic = {'S', 'D', 'C', 'A'};
constexpr uint8_t kVersionMajor = 1;  // a receiver drops other majors (incompatible)
constexpr uint8_t kVersionMinor = 0;  // newer minors only add: message types, blocks, fields
constexpr std::size_t kHeaderBytes = 16;
constexpr std::size_t kDatagramLimit = 1200;  // every datagram is shorter: no IP fragmentation
constexpr double kLandmarkStep = 1e-5;        // metres per landmark unit (10 micrometres)
constexpr std::size_t kNeutralChunkVertices = 80;
constexpr std::size_t kMaxNeutralVertices = 4096;
constexpr std::size_t kMaxProfileName = 64;

enum class MessageType : uint8_t { frame = 1, profile = 2, neutral_chunk = 3, request = 4 };
enum class BlockType : uint16_t { weights = 1, head_pose = 2, eye_poses = 3, landmarks = 4 };
enum class RequestKind : uint8_t { profile = 1, neutral = 2 };

struct Envelope {
  uint8_t minor = kVersionMinor;
  MessageType type = MessageType::frame;
  uint32_t session_id = 0;
  uint32_t sequence = 0;
};

// A landmark profile: the ARKit face-mesh vertices whose positions frames carry, in order.
struct Profile {
  uint32_t id = 0;  // profile_id_of(indices)
  std::string name;
  std::vector<uint16_t> indices;
};
uint32_t profile_id_of(const std::vector<uint16_t>& indices);

// Part of the user's neutral face mesh, for calibration (all chunks share neutral_id).
struct NeutralChunk {
  uint32_t neutral_id = 0;  // neutral_id_of(all vertices)
  uint16_t total_vertices = 0;
  uint16_t first_vertex = 0;
  std::vector<float> xyz;  // 3 floats per vertex of this chunk
};
uint32_t neutral_id_of(const float* xyz, std::size_t vertex_count);
// The chunks, in order, that carry a whole neutral mesh.
std::vector<NeutralChunk> split_neutral(const float* xyz, std::size_t vertex_count);

// Receiver -> sender: send the profile `id`, or the neutral mesh.
struct Request {
  RequestKind what = RequestKind::profile;
  uint32_t id = 0;
};

// One decoded datagram: the member that envelope.type names is filled.
struct Message {
  Envelope envelope;
  Frame frame;
  Profile profile;
  NeutralChunk neutral;
  Request request;
};

struct Verdict {
  DropReason reason = DropReason::none;
  const char* detail = "";  // static text saying what was wrong
};

// The body of a profile message (id, count, name, indices), which recordings store too.
// write_profile_body checks the profile and throws softdeca::Error when it is invalid.
void write_profile_body(ByteWriter& w, const Profile& profile);
Verdict read_profile_body(ByteReader& r, Profile& profile);

// Parses one datagram. Never reads outside [data, data + size).
Verdict decode(const uint8_t* data, std::size_t size, Message& out);

// Encoders replace `out` with one datagram. They throw softdeca::Error for input that the
// format cannot carry (non-finite values, too many landmarks, landmarks outside
// [-0.32768, 0.32767] m).
// The frame's session_id and sequence go into the header.
void encode_frame(const Frame& frame, std::vector<uint8_t>& out);
void encode_profile(uint32_t session_id, uint32_t sequence, const Profile& profile,
                    std::vector<uint8_t>& out);
void encode_neutral_chunk(uint32_t session_id, uint32_t sequence, const NeutralChunk& chunk,
                          std::vector<uint8_t>& out);
void encode_request(uint32_t session_id, uint32_t sequence, const Request& request,
                    std::vector<uint8_t>& out);

}  // namespace softdeca::stream::wire
