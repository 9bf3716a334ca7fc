// Live Link Face's UDP packet, version 6 (docs/protocol.md), big-endian: version byte, device id and
// subject name (int32 length + UTF-8 each), frame time (int32 frame, float subframe, int32 fps
// numerator and denominator), a value count byte and that many float32 values (livelinkface_layout.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "stream/frame.h"
#include "stream/wire_format.h"

namespace softdeca::stream::livelinkface {

constexpr uint8_t kPacketVersion = 6;
constexpr std::size_t kMaxNameBytes = 255;     // device id and subject name, each
constexpr std::size_t kMaxPacketBytes = 2048;  // real packets are 264 to 774 bytes

struct PacketInfo {
  std::string device_id;
  std::string subject;
  int32_t frame_number = 0;
  float subframe = 0;
  int32_t fps_numerator = 60;
  int32_t fps_denominator = 1;
};

// Decodes into the canonical frame: weights reordered, head and eye angles as quaternions
// (position zero: the format has none), capture_time = (frame + subframe) / fps, session_id
// from device id and subject. A packet with no values means the face is lost.
wire::Verdict decode_packet(const uint8_t* data, std::size_t size, Frame& frame, PacketInfo& info);

// Encodes a frame as a packet; the frame time comes from capture_time at info's rate.
void encode_packet(const Frame& frame, const PacketInfo& info, std::vector<uint8_t>& out);

// The session id that decode_packet gives a device and subject.
uint32_t session_id_of(const std::string& device_id, const std::string& subject);

}  // namespace softdeca::stream::livelinkface
