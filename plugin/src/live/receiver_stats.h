// What a receiver counts (docs/protocol.md, "Receiver statistics").
#pragma once

#include <cstdint>

namespace softdeca::live {

struct ReceiverStats {
  uint64_t datagrams = 0;         // every datagram read from the socket
  uint64_t frames = 0;            // well-formed frame messages
  uint64_t control_messages = 0;  // well-formed profile, neutral and request messages
  uint64_t delivered = 0;         // frames that came out of the jitter buffer
  // Dropped as malformed, by reason; `malformed` is their sum.
  uint64_t malformed = 0;
  uint64_t undersized = 0;
  uint64_t oversized = 0;
  uint64_t bad_magic = 0;
  uint64_t incompatible_version = 0;
  uint64_t bad_length = 0;
  uint64_t bad_value = 0;
  uint64_t unknown_type = 0;  // messages of a newer minor version: ignored, not malformed
  // Sequence and timing.
  uint64_t duplicates = 0;     // dropped: seen before
  uint64_t reordered = 0;      // arrived after a newer datagram (delivered if not late)
  uint64_t late = 0;           // dropped: arrived after a newer frame had been delivered
  uint64_t lost = 0;           // sequence numbers never received (so far)
  uint64_t expected = 0;       // sequence numbers the senders used
  uint64_t overflowed = 0;     // delivered frames dropped because nobody took them
  uint64_t session_changes = 0;
  uint64_t clock_resyncs = 0;  // the sender's capture clock jumped
  uint64_t requests_sent = 0;  // profile or neutral requests to the sender
  uint64_t foreign = 0;        // dropped: from another sender while the session was held
  uint64_t rate_limited = 0;   // dropped: over the per-source rate limit
  uint64_t recording_dropped = 0;  // delivered frames (and records) the disk could not take
  double frame_rate_hz = 0;    // delivered frames per second, over the last ~2 s
  double loss_ratio = 0;       // lost / expected
  double latency_p50_ms = 0;   // arrival at the socket -> frame available, recent frames
  double latency_p99_ms = 0;
};

}  // namespace softdeca::live
