// One frame thread at a time per avatar: a second thread gets Error(BUSY) instead of a race.
#pragma once

#include <atomic>

#include "core/error.h"

namespace softdeca::runtime {

class FrameGuard {
 public:
  explicit FrameGuard(std::atomic<bool>& busy) : busy_(busy) {
    if (busy_.exchange(true, std::memory_order_acquire))
      throw Error(SOFTDECA_ERROR_BUSY, "the avatar is in use by a frame on another thread (one frame thread at a time)");
  }
  ~FrameGuard() { busy_.store(false, std::memory_order_release); }
  FrameGuard(const FrameGuard&) = delete;
  FrameGuard& operator=(const FrameGuard&) = delete;

 private:
  std::atomic<bool>& busy_;
};

}  // namespace softdeca::runtime
