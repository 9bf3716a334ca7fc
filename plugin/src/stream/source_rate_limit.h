// Per-source rate limit of a receiver: a token bucket per sender address and port. The table
// of sources is bounded (the least recently heard source is forgotten first), so a flood from
// many ports or spoofed addresses costs a fixed amount of memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>

#include "stream/udp_socket.h"

namespace softdeca::stream {

class SourceRateLimit {
 public:
  // `rate`: datagrams per second each source may send on average; 0 or less: no limit.
  // A source may send a burst of rate/4 (at least 8) datagrams at once.
  explicit SourceRateLimit(double rate, std::size_t max_sources = 256);

  // True when the datagram from `from` at time `now` (seconds) is within its source's rate.
  bool allow(const Endpoint& from, double now);
  std::size_t sources() const { return buckets_.size(); }

 private:
  struct Bucket {
    double tokens = 0;
    double last = 0;
  };
  double rate_, burst_;
  std::size_t max_sources_;
  std::unordered_map<std::string, Bucket> buckets_;
};

// The bytes that identify a sender (address and port).
std::string endpoint_key(const Endpoint& e);

}  // namespace softdeca::stream
