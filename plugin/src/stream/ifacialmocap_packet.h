// iFacialMocap's UDP text packet (docs/protocol.md): "name-value|...|=head#rx,ry,rz,px,py,pz|
// rightEye#rx,ry,rz|leftEye#rx,ry,rz|", values 0-100, names with _L/_R, angles in degrees.
// Version 2 of the app separates name and value with '&' instead of '-'; both are accepted.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "stream/frame.h"
#include "stream/wire_format.h"

namespace softdeca::stream::ifacialmocap {

constexpr std::size_t kMaxPacketBytes = 8192;

// Which of the 52 weights the packet named: a packet need not carry all of them, and a missing
// one is "unchanged", not zero (the receiver keeps the session's previous value).
using Presence = std::array<bool, kBlendshapeCount>;

// Decodes into the canonical frame (capture_time stays 0: the format has no clock). Unknown
// names and unnamed fields are skipped; a packet with no known blendshape is not iFacialMocap.
wire::Verdict decode_packet(const uint8_t* data, std::size_t size, Frame& frame, Presence& present);

// Encodes a frame (weights rounded to integers 0-100); `separator` is '-' (v1) or '&' (v2).
std::string encode_packet(const Frame& frame, char separator = '-');

// iFacialMocap's spelling of canonical shape i ("eyeBlink_L"; jawLeft and mouthLeft unchanged).
std::string wire_name(std::size_t canonical_index);

}  // namespace softdeca::stream::ifacialmocap
