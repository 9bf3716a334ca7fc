// Why a datagram was dropped. Every parser returns one of these instead of throwing, so the
// receiver counts hostile and broken input per reason (docs/protocol.md, "Hostile input").
#pragma once

#include <cstdint>

namespace softdeca::stream {

enum class DropReason : uint8_t {
  none = 0,
  undersized,            // shorter than the smallest message of its format
  oversized,             // 1,200 bytes or more (ours), or over a format's packet limit
  bad_magic,             // not a datagram of any format the receiver accepts
  incompatible_version,  // a major version (ours) or packet version (Live Link Face) we lack
  bad_length,            // a length or count field disagrees with the datagram's size
  bad_value,             // NaN/Inf, an out-of-range index, an id that does not match its data
  unknown_type,          // a message type of a newer minor version: ignored, not malformed
};

const char* drop_reason_name(DropReason reason);

}  // namespace softdeca::stream
