#include "bench_bandwidth.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <numeric>
#include <vector>

namespace softdeca::cli {

namespace {
volatile std::uint64_t sink;  // where each pass's sum goes, so that no pass can be left out

// Eight independent sums: the adds never wait on each other, so the loads are the limit.
std::uint64_t sum_words(const std::uint64_t* w, std::size_t n) {
  std::uint64_t s[8] = {};
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8)
    for (int k = 0; k < 8; ++k) s[k] += w[i + static_cast<std::size_t>(k)];
  for (; i < n; ++i) s[0] += w[i];
  return std::accumulate(s, s + 8, std::uint64_t{0});
}
}  // namespace

double streaming_read_gb_s(std::size_t bytes, int passes) {
  std::vector<std::uint64_t> words(bytes / sizeof(std::uint64_t));
  std::iota(words.begin(), words.end(), std::uint64_t{1});  // every page touched before timing
  double best_s = 0;
  for (int p = 0; p < passes; ++p) {
    const auto t0 = std::chrono::steady_clock::now();
    sink = sum_words(words.data(), words.size());
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best_s = p == 0 ? s : std::min(best_s, s);
  }
  return static_cast<double>(words.size() * sizeof(std::uint64_t)) / best_s / 1e9;
}

}  // namespace softdeca::cli
