// Orders frames by capture time and holds each until `delay` seconds after the moment it would
// have arrived over the fastest path seen, so that frames reordered or delayed by less than
// the delay still come out in order. The sender's clock is mapped onto ours by the minimum of
// (arrival - capture time) over the last seconds, which needs no clock synchronisation.
#pragma once

#include <cstddef>
#include <deque>
#include <limits>
#include <utility>

#include "stream/frame.h"

namespace softdeca::stream {

class JitterBuffer {
 public:
  static constexpr double kOffsetWindow = 10.0;   // seconds of arrivals the clock mapping uses
  static constexpr double kMaxClockJump = 5.0;    // larger jumps of capture time: a new clock
  static constexpr std::size_t kCapacity = 1024;  // beyond this the oldest frames go out at once

  enum class Outcome { queued, late, duplicate, resync };

  explicit JitterBuffer(double delay_seconds) : delay_(delay_seconds) {}

  // Queues a frame that arrived at `arrival` (seconds, our clock). late: older than a frame
  // already released; duplicate: the same capture time as a queued or released one; resync:
  // queued, after a clock jump released everything queued before it.
  Outcome insert(const Frame& frame, double arrival);
  // Takes the oldest frame if its time has come at `now`.
  bool pop_due(double now, Frame& out);
  // Takes the oldest frame whatever the time (to flush at shutdown).
  bool pop_any(Frame& out);
  // When the oldest frame falls due (-inf: now; +inf: nothing queued).
  double next_due() const;
  std::size_t size() const { return queue_.size(); }

 private:
  double offset() const { return offsets_.empty() ? 0.0 : offsets_.front().second; }
  void take_front(Frame& out);

  double delay_;
  std::deque<Frame> queue_;  // capture-time order; the first flush_ entries are due at once
  std::size_t flush_ = 0;
  std::deque<std::pair<double, double>> offsets_;  // (arrival, arrival - capture), offsets rising
  bool started_ = false;
  double newest_capture_ = 0;
  double last_released_ = -std::numeric_limits<double>::infinity();
};

}  // namespace softdeca::stream
