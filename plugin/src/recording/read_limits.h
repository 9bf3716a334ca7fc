// The size over which a recording or a CSV take is refused before it is read: a crafted file
// (a terabyte of sparse zeros behind a valid header) fails at once with a message saying how
// to raise the limit, instead of taking the reader hours.
#pragma once

#include <cstdint>
#include <string>

#include "core/error.h"

namespace softdeca::recording {

struct ReadLimits {
  std::uint64_t max_bytes = std::uint64_t{1} << 30;  // 1 GiB: hours of frames at 60 Hz
};

inline std::string mib_text(std::uint64_t bytes) {
  return std::to_string((bytes + (std::uint64_t{1} << 20) - 1) >> 20) + " MiB";
}

// Throws softdeca::Error (FORMAT) naming the file, its size and the limit.
inline void require_within(const std::string& path, std::uint64_t size, const ReadLimits& limits, const char* what) {
  if (size <= limits.max_bytes && size <= std::uint64_t{SIZE_MAX}) return;
  throw Error(SOFTDECA_ERROR_FORMAT, path + " is " + mib_text(size) + ", over the limit of " +
                                         mib_text(limits.max_bytes) + " for " + what +
                                         " (softdeca: --max-mib; C++: ReadLimits::max_bytes)");
}

}  // namespace softdeca::recording
