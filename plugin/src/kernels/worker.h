// The avatar's own helper threads for the frame's data-parallel passes. run(f) calls f(part,
// parts) once for every part 0..parts-1. Parts are claimed, not assigned: the caller claims
// parts too, so when a helper is late (a busy machine, a descheduled thread) the caller simply
// runs the remaining parts itself and a frame is never slower than with one thread by more than
// the claim. Helpers spin briefly after a job (the passes of a frame follow each other within
// microseconds) and then sleep, so an idle avatar costs no CPU. Passes must not throw.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace softdeca::kernels {

class Worker {
 public:
  explicit Worker(std::size_t threads);  // threads >= 1, including the caller
  ~Worker();
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  std::size_t parts() const { return helpers_.size() + 1; }

  template <class F>
  void run(F& f) {
    if (helpers_.empty()) {
      f(std::size_t{0}, std::size_t{1});
      return;
    }
    dispatch(&call<F>, &f);
  }

 private:
  template <class F>
  static void call(void* ctx, std::size_t part, std::size_t parts) {
    (*static_cast<F*>(ctx))(part, parts);
  }
  void dispatch(void (*fn)(void*, std::size_t, std::size_t), void* ctx);
  void work(std::uint64_t job);  // claim and run parts of `job` until none is left
  void loop();

  std::vector<std::thread> helpers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::atomic<std::uint64_t> posted_{0};  // the current job's number
  std::atomic<std::uint64_t> claim_{0};   // job number << 32 | next unclaimed part
  std::atomic<std::size_t> done_{0};      // parts of the current job finished
  std::atomic<bool> stop_{false};
  void (*fn_)(void*, std::size_t, std::size_t) = nullptr;
  void* ctx_ = nullptr;
};

}  // namespace softdeca::kernels
