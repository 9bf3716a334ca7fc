// The --max-mib option of the commands that read recordings and CSV takes: the size over which
// a file is refused (recording/recording_index.h), so that a crafted huge file fails at once.
#pragma once

#include <cmath>
#include <cstdint>

#include "options.h"
#include "recording/read_limits.h"

namespace softdeca::cli {

inline void declare_read_limits(Options& o) {
  o.option("--max-mib", "MIB", "refuse recordings and CSV takes larger than this", "1024");
}

inline recording::ReadLimits read_limits(const Options& o) {
  const double mib = o.number("--max-mib");
  if (!(mib >= 1 && mib <= 1048576) || mib != std::floor(mib))
    throw UsageError("--max-mib must be a whole number in [1, 1048576]");
  recording::ReadLimits limits;
  limits.max_bytes = static_cast<std::uint64_t>(mib) << 20;
  return limits;
}

}  // namespace softdeca::cli
