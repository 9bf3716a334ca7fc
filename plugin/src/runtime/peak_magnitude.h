// The largest magnitude of an array: what a frame's sums of it can reach, for proving a frame
// finite before it runs (Avatar::in_place).
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

namespace softdeca::runtime {

// max |v[i]|, infinite when a value is not finite (so a bound built from it fails).
inline float peak_magnitude(const float* v, std::size_t n) {
  float peak = 0.0f;
  for (std::size_t i = 0; i < n; ++i) {
    const float a = std::fabs(v[i]);
    if (!(a <= std::numeric_limits<float>::max())) return std::numeric_limits<float>::infinity();
    peak = a > peak ? a : peak;
  }
  return peak;
}

}  // namespace softdeca::runtime
