// The avatar's own helper threads for the frame's data-parallel passes. run(f) calls f(part,
// parts) for every part: part 0 on the calling thread, the others on the helpers. Helpers spin
// briefly after a job (the passes of one frame follow each other within microseconds) and then
// sleep, so an idle avatar costs no CPU. The passes given to run() must not throw.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace softdeca::runtime {

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
  void loop(std::size_t part);

  std::vector<std::thread> helpers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::atomic<std::uint64_t> posted_{0};
  std::atomic<std::size_t> pending_{0};
  std::atomic<bool> stop_{false};
  void (*fn_)(void*, std::size_t, std::size_t) = nullptr;
  void* ctx_ = nullptr;
};

}  // namespace softdeca::runtime
