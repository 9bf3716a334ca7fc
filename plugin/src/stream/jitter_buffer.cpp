#include "stream/jitter_buffer.h"

#include <algorithm>
#include <cmath>

namespace softdeca::stream {

JitterBuffer::Outcome JitterBuffer::insert(const Frame& f, double arrival) {
  const double capture = f.capture_time;
  Outcome outcome = Outcome::queued;
  if (started_ && std::fabs(capture - newest_capture_) > kMaxClockJump) {
    // A new clock (sender restart, timecode past midnight): what is queued goes out now, and
    // the mapping and the order start afresh.
    flush_ = queue_.size();
    offsets_.clear();
    last_released_ = -std::numeric_limits<double>::infinity();
    newest_capture_ = capture;
    outcome = Outcome::resync;
  }
  if (capture < last_released_) return Outcome::late;
  if (capture == last_released_) return Outcome::duplicate;
  const auto first = queue_.begin() + static_cast<std::ptrdiff_t>(flush_);
  const auto at = std::upper_bound(first, queue_.end(), capture,
                                   [](double t, const Frame& q) { return t < q.capture_time; });
  if (at != first && (at - 1)->capture_time == capture) return Outcome::duplicate;

  started_ = true;
  newest_capture_ = std::max(newest_capture_, capture);
  // Sliding-window minimum: drop samples that a newer, smaller one makes irrelevant.
  const double sample = arrival - capture;
  while (!offsets_.empty() && offsets_.back().second >= sample) offsets_.pop_back();
  offsets_.emplace_back(arrival, sample);
  while (offsets_.front().first < arrival - kOffsetWindow) offsets_.pop_front();
  queue_.insert(at, f);
  return outcome;
}

double JitterBuffer::next_due() const {
  if (queue_.empty()) return std::numeric_limits<double>::infinity();
  if (flush_ > 0 || queue_.size() > kCapacity) return -std::numeric_limits<double>::infinity();
  return queue_.front().capture_time + offset() + delay_;
}

bool JitterBuffer::pop_due(double now, Frame& out) {
  if (queue_.empty() || next_due() > now) return false;
  take_front(out);
  return true;
}

bool JitterBuffer::pop_any(Frame& out) {
  if (queue_.empty()) return false;
  take_front(out);
  return true;
}

void JitterBuffer::take_front(Frame& out) {
  out = queue_.front();
  queue_.pop_front();
  if (flush_ > 0) {
    --flush_;  // released under the old clock: no bearing on the new order
  } else {
    last_released_ = out.capture_time;
  }
}

}  // namespace softdeca::stream
