#include "stream/sequence_tracker.h"

namespace softdeca::stream {

Arrival SequenceTracker::observe(uint32_t s) {
  const auto restart = [&] {
    started_ = true;
    first_ = newest_ = s;
    seen_.reset();
    seen_.set(s % kWindow);
    ++expected_;
  };
  if (!started_) {
    restart();
    return Arrival::in_order;
  }
  const auto d = static_cast<int32_t>(s - newest_);
  if (d > 0) {
    if (static_cast<uint32_t>(d) > kMaxJump) {
      restart();
      return Arrival::restart;
    }
    // Slots that leave the window become the new numbers' slots: clear them.
    const uint32_t steps = static_cast<uint32_t>(d) < kWindow ? static_cast<uint32_t>(d) : kWindow;
    for (uint32_t k = 1; k <= steps; ++k) seen_.reset((newest_ + k) % kWindow);
    seen_.set(s % kWindow);
    missing_ += static_cast<uint32_t>(d) - 1;
    expected_ += static_cast<uint32_t>(d);
    newest_ = s;
    return Arrival::in_order;
  }
  if (d == 0) return Arrival::duplicate;
  if (static_cast<uint32_t>(-static_cast<int64_t>(d)) >= kWindow || static_cast<int32_t>(s - first_) < 0)
    return Arrival::stale;
  if (seen_.test(s % kWindow)) return Arrival::duplicate;
  seen_.set(s % kWindow);
  --missing_;  // it was counted missing when the newer one skipped it
  return Arrival::reordered;
}

}  // namespace softdeca::stream
