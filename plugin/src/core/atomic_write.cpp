#include <atomic>
#include <chrono>
#include <cstdint>

#include "core/atomic_write.h"

namespace softdeca {

std::string temporary_sibling(const std::string& path, unsigned long process_id) {
  static std::atomic<std::uint64_t> calls{0};
  // The clock tells apart a process that reuses an earlier one's id while that one's file is left.
  const auto now = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  const std::string::size_type slash = path.find_last_of("/\\");
  const std::string folder = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  return folder + "." + name + "." + std::to_string(process_id) + "-" + std::to_string(calls.fetch_add(1)) + "-" +
         std::to_string(now % 1000000007u) + ".tmp";
}

}  // namespace softdeca
