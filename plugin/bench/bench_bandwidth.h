// The machine's streaming read bandwidth on one thread (a frame runs on one): what a frame that
// reads its tables from memory can move at most, to set its bytes against (bench-runtime).
#pragma once

#include <cstddef>

namespace softdeca::cli {

constexpr std::size_t kBandwidthBufferBytes = std::size_t{256} << 20;  // far beyond any last-level cache
constexpr int kBandwidthPasses = 10;

// Bytes per second of a sum of 64-bit words over `bytes` of memory written beforehand, best of
// `passes` passes, in GB/s (1e9 bytes per second).
double streaming_read_gb_s(std::size_t bytes = kBandwidthBufferBytes, int passes = kBandwidthPasses);

}  // namespace softdeca::cli
