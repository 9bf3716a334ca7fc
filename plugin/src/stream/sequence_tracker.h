// Loss, reordering and duplicates of one sender's datagrams, from their sequence numbers
// (serial arithmetic, so the 32-bit counter may wrap).
#pragma once

#include <bitset>
#include <cstddef>
#include <cstdint>

namespace softdeca::stream {

enum class Arrival : uint8_t {
  in_order,   // newer than any before
  reordered,  // older than the newest, fills a gap
  duplicate,  // seen before
  stale,      // older than the window or the first one seen: cannot tell, dropped
  restart,    // a jump too far to be loss: the sender restarted its counter; counting restarts
};

class SequenceTracker {
 public:
  static constexpr std::size_t kWindow = 1024;     // how far back reordering is recognised
  static constexpr uint32_t kMaxJump = 1u << 16;   // a larger forward jump is a restart

  Arrival observe(uint32_t sequence);
  uint64_t lost() const { return missing_; }        // skipped and not (yet) arrived
  uint64_t expected() const { return expected_; }   // sequence numbers from first to newest

 private:
  bool started_ = false;
  uint32_t first_ = 0;  // since the (re)start
  uint32_t newest_ = 0;
  uint64_t missing_ = 0;
  uint64_t expected_ = 0;
  std::bitset<kWindow> seen_;  // bit s % kWindow for s in (newest - kWindow, newest]
};

}  // namespace softdeca::stream
