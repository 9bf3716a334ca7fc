#include "sim/thread_pool.h"

#include <algorithm>
#include <exception>

namespace softdeca::sim {

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { work(i); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (auto& t : workers_) t.join();
}

namespace {
// Chunk `id` of `parts` equal chunks of [0, n).
std::pair<std::size_t, std::size_t> chunk(std::size_t n, int parts, int id) {
  const std::size_t p = static_cast<std::size_t>(parts), i = static_cast<std::size_t>(id);
  return {n * i / p, n * (i + 1) / p};
}
}  // namespace

void ThreadPool::parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t, int)>& body) {
  if (n == 0) return;
  if (workers_.empty() || n == 1) {
    body(0, n, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    body_ = &body;
    n_ = n;
    pending_ = static_cast<int>(workers_.size());
    error_ = nullptr;
    ++generation_;
  }
  start_.notify_all();
  std::exception_ptr mine;
  try {
    const auto [b, e] = chunk(n, size(), 0);
    if (b < e) body(b, e, 0);
  } catch (...) {
    mine = std::current_exception();
  }
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return pending_ == 0; });
  body_ = nullptr;
  if (mine) std::rethrow_exception(mine);
  if (error_) std::rethrow_exception(error_);
}

void ThreadPool::work(int id) {
  std::size_t seen = 0;
  for (;;) {
    const std::function<void(std::size_t, std::size_t, int)>* body;
    std::size_t n;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      body = body_;
      n = n_;
    }
    std::exception_ptr err;
    try {
      const auto [b, e] = chunk(n, size(), id);
      if (b < e) (*body)(b, e, id);
    } catch (...) {
      err = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (err && !error_) error_ = err;
      if (--pending_ == 0) done_.notify_one();
    }
  }
}

}  // namespace softdeca::sim
