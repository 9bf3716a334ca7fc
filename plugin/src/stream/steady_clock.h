// This host's monotonic clock in seconds: receive times, latency, release times. On Linux it is
// CLOCK_MONOTONIC, the clock of Python's time.monotonic(), so a local sender can stamp frames
// on the same clock.
#pragma once

#include <chrono>

namespace softdeca::stream {

inline double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace softdeca::stream
