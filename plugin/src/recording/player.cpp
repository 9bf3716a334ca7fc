#include "recording/player.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "recording/frame_interpolation.h"

namespace softdeca::recording {

Player::Player(Recording recording) : rec_(std::move(recording)) {
  require(!rec_.frames.empty(), "the recording has no frames", SOFTDECA_ERROR_FORMAT);
  // Recorders write in capture order; a converted or hand-made file might not be.
  std::stable_sort(rec_.frames.begin(), rec_.frames.end(),
                   [](const stream::Frame& a, const stream::Frame& b) { return a.capture_time < b.capture_time; });
  start_ = rec_.frames.front().capture_time;
  duration_ = rec_.frames.back().capture_time - start_;
}

double Player::frame_time(std::size_t i) const { return rec_.frames.at(i).capture_time - start_; }

stream::Frame Player::frame_at(double time) const {
  const double t = start_ + std::clamp(time, 0.0, duration_);
  const auto& frames = rec_.frames;
  const auto after = std::upper_bound(frames.begin(), frames.end(), t,
                                      [](double v, const stream::Frame& f) { return v < f.capture_time; });
  if (after == frames.begin()) return frames.front();
  if (after == frames.end()) return frames.back();
  const stream::Frame& a = *(after - 1);
  const stream::Frame& b = *after;
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
