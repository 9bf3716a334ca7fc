// A small fixed pool of worker threads for data-parallel loops. Owned by a simulator (no
// global state); the calling thread takes part, so a pool of size 1 runs everything inline.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace softdeca::sim {

class ThreadPool {
 public:
  // threads <= 0: one per hardware thread.
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(begin, end, worker) on disjoint chunks covering [0, n), at most `size()` of
  // them, and returns when all are done. worker is in [0, size()). Exceptions thrown by a
  // chunk are rethrown here (the first one). Not reentrant: one loop at a time.
  void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t, int)>& body);

 private:
  void work(int id);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  const std::function<void(std::size_t, std::size_t, int)>* body_ = nullptr;
  std::size_t n_ = 0;
  std::size_t generation_ = 0;
  int pending_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

}  // namespace softdeca::sim
