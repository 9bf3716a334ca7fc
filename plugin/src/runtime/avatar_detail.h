// What the avatar's source files share (avatar.cpp: state and inputs; avatar_prepare.cpp:
// prepare; avatar_evaluate.cpp: frames; avatar_frame_bytes.cpp: their bytes): timing, the
// models' indices, the finiteness check.
#pragma once

#include <chrono>
#include <cmath>
#include <cstddef>

namespace softdeca::runtime::avatar_detail {

using Clock = std::chrono::steady_clock;
inline double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

constexpr int kSoftDeca = 0, kSparse = 1;  // Preparation::dynamics, DynamicsState's model

inline bool all_finite(const float* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

}  // namespace softdeca::runtime::avatar_detail
