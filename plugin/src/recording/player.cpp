#include "recording/player.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "recording/frame_interpolation.h"

namespace softdeca::recording {

Player::Player(RecordingIndex index) : index_(std::move(index)) {
  require(index_.frame_count() > 0, "the recording has no frames", SOFTDECA_ERROR_FORMAT);
  index_.sort_by_capture_time();  // recorders write in capture order; a converted or hand-made file might not be
  start_ = index_.capture_time(0);
  duration_ = index_.capture_time(index_.frame_count() - 1) - start_;
}

Player::Player(const Recording& recording) : Player(RecordingIndex::from_frames(recording, recording.frames)) {}

double Player::frame_time(std::size_t i) const { return index_.capture_time(i) - start_; }

stream::Frame Player::frame_at(double time) const {
  const double t = start_ + std::clamp(time, 0.0, duration_);
  // The first frame after t: times are sorted.
  std::size_t lo = 0, hi = index_.frame_count();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (t < index_.capture_time(mid)) hi = mid;
    else lo = mid + 1;
  }
  if (lo == 0) return index_.frame(0);
  if (lo == index_.frame_count()) return index_.frame(lo - 1);
  const stream::Frame a = index_.frame(lo - 1);
  const stream::Frame b = index_.frame(lo);
  const double span = b.capture_time - a.capture_time;
  return span > 0 ? interpolate(a, b, (t - a.capture_time) / span) : a;
}

void Player::seek(double time) {
  require(std::isfinite(time), "seek time is not finite", SOFTDECA_ERROR_NON_FINITE);
  position_ = std::clamp(time, 0.0, duration_);
}

void Player::set_speed(double speed) {
  require(std::isfinite(speed) && speed >= 0 && speed <= 1000, "speed must be in [0, 1000]");
  speed_ = speed;
}

bool Player::advance(double dt) {
  require(std::isfinite(dt) && dt >= 0, "dt must be finite and >= 0");
  double p = position_ + dt * speed_;
  if (p <= duration_) {
    position_ = p;
    return false;
  }
  if (loop_ && duration_ > 0) {
    position_ = std::fmod(p, duration_);
    return false;
  }
  position_ = duration_;
  return true;
}

}  // namespace softdeca::recording
