// Shared by the bench runs that measure a step's memory in a child process: this process's
// resident memory as Linux reports it, and the reset of its peak.
#pragma once

#include <cstdint>

namespace softdeca::cli {

// A line of /proc/self/status in bytes ("VmRSS", "VmHWM"); 0 where there is none.
std::uint64_t status_bytes(const char* key);

// Resets VmHWM to the current RSS (Linux 4.0 and later); false where that is refused.
bool reset_peak();

}  // namespace softdeca::cli
