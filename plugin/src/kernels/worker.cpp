#include "kernels/worker.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SOFTDECA_PAUSE() _mm_pause()
#elif defined(__aarch64__) && defined(__GNUC__)
#define SOFTDECA_PAUSE() __asm__ __volatile__("yield")  // the spin-wait hint, not a system call
#else
#define SOFTDECA_PAUSE() std::this_thread::yield()
#endif

namespace softdeca::kernels {

namespace {
constexpr int kSpinsBeforeSleep = 20000;  // ~0.5 ms of pause instructions
constexpr int kSpinsBeforeYield = 2000;
}  // namespace

Worker::Worker(std::size_t threads) {
  for (std::size_t p = 1; p < (threads < 1 ? 1 : threads); ++p) helpers_.emplace_back([this] { loop(); });
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

void Worker::work(std::uint64_t job) {
  const std::size_t parts = this->parts();
  std::uint64_t c = claim_.load(std::memory_order_acquire);
  for (;;) {
    if ((c >> 32) != (job & 0xFFFFFFFFu) || (c & 0xFFFFFFFFu) >= parts) return;  // another job, or all claimed
    if (!claim_.compare_exchange_weak(c, c + 1, std::memory_order_acq_rel, std::memory_order_acquire)) continue;
    // The job cannot end before this claimed part is done, so fn_ and ctx_ are still its own.
    fn_(ctx_, static_cast<std::size_t>(c & 0xFFFFFFFFu), parts);
    done_.fetch_add(1, std::memory_order_acq_rel);
    c = claim_.load(std::memory_order_acquire);
  }
}

void Worker::dispatch(void (*fn)(void*, std::size_t, std::size_t), void* ctx) {
  fn_ = fn;
  ctx_ = ctx;
  done_.store(0, std::memory_order_relaxed);
  std::uint64_t job;
  {
    // Under the mutex so a helper about to sleep either sees the new job or gets the notify.
    std::lock_guard<std::mutex> lock(mutex_);
    job = posted_.load(std::memory_order_relaxed) + 1;
    claim_.store((job & 0xFFFFFFFFu) << 32, std::memory_order_release);
    posted_.store(job, std::memory_order_release);
  }
  wake_.notify_all();
  work(job);
  for (int spins = 0; done_.load(std::memory_order_acquire) != parts(); ++spins) {
    if (spins < kSpinsBeforeYield) SOFTDECA_PAUSE();
    else std::this_thread::yield();
  }
}

void Worker::loop() {
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
    work(seen);
  }
}

}  // namespace softdeca::kernels
