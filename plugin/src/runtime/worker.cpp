#include "runtime/worker.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SOFTDECA_PAUSE() _mm_pause()
#else
#define SOFTDECA_PAUSE() std::this_thread::yield()
#endif

namespace softdeca::runtime {

namespace {
constexpr int kSpinsBeforeSleep = 20000;  // ~0.5 ms of pause instructions
constexpr int kSpinsBeforeYield = 2000;
}  // namespace

Worker::Worker(std::size_t threads) {
  for (std::size_t p = 1; p < (threads < 1 ? 1 : threads); ++p) helpers_.emplace_back([this, p] { loop(p); });
}

Worker::~Worker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_.store(true, std::memory_order_relaxed);
    posted_.fetch_add(1, std::memory_order_release);
  }
  wake_.notify_all();
  for (auto& t : helpers_) t.join();
}

void Worker::dispatch(void (*fn)(void*, std::size_t, std::size_t), void* ctx) {
  fn_ = fn;
  ctx_ = ctx;
  pending_.store(helpers_.size(), std::memory_order_relaxed);
  {
    // Under the mutex so a helper about to sleep either sees the new job or gets the notify.
    std::lock_guard<std::mutex> lock(mutex_);
    posted_.fetch_add(1, std::memory_order_release);
  }
  wake_.notify_all();
  fn(ctx, 0, parts());
  for (int spins = 0; pending_.load(std::memory_order_acquire) != 0; ++spins) {
    if (spins < kSpinsBeforeYield) SOFTDECA_PAUSE();
    else std::this_thread::yield();
  }
}

void Worker::loop(std::size_t part) {
  std::uint64_t seen = 0;
  for (;;) {
    int spins = 0;
    while (posted_.load(std::memory_order_acquire) == seen) {
      if (++spins < kSpinsBeforeSleep) {
        SOFTDECA_PAUSE();
        continue;
      }
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return posted_.load(std::memory_order_acquire) != seen; });
    }
    seen = posted_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_relaxed)) return;
    fn_(ctx_, part, parts());
    pending_.fetch_sub(1, std::memory_order_acq_rel);
  }
}

}  // namespace softdeca::runtime
