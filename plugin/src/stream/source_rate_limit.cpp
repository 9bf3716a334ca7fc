#include "stream/source_rate_limit.h"

#include <algorithm>

namespace softdeca::stream {

std::string endpoint_key(const Endpoint& e) {
  return std::string(reinterpret_cast<const char*>(&e.address), static_cast<std::size_t>(e.length));
}

SourceRateLimit::SourceRateLimit(double rate, std::size_t max_sources)
    : rate_(rate), burst_(std::max(8.0, rate / 4)), max_sources_(std::max<std::size_t>(1, max_sources)) {}

bool SourceRateLimit::allow(const Endpoint& from, double now) {
  if (!(rate_ > 0)) return true;
  const std::string key = endpoint_key(from);
  auto it = buckets_.find(key);
  if (it == buckets_.end()) {
    if (buckets_.size() >= max_sources_) {
      auto oldest = buckets_.begin();
      for (auto b = buckets_.begin(); b != buckets_.end(); ++b)
        if (b->second.last < oldest->second.last) oldest = b;
      buckets_.erase(oldest);
    }
    it = buckets_.emplace(key, Bucket{burst_, now}).first;
  }
  Bucket& b = it->second;
  b.tokens = std::min(burst_, b.tokens + std::max(0.0, now - b.last) * rate_);
  b.last = now;
  if (b.tokens < 1) return false;
  b.tokens -= 1;
  return true;
}

}  // namespace softdeca::stream
