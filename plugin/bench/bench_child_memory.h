// How bench-reliability measures the memory of one piece of work: in a child process of its own
// (one run's peak cannot hide another's), with the child's peak resident memory (VmHWM) reset
// just before the work, so that the figure is what the work itself added (Linux 4.0 and later).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace softdeca::cli {

struct ChildPeak {
  std::uint64_t increase = 0;  // VmHWM after the work over VmRSS before it
  std::string report;          // what the work returned, or why `prepare` failed
  bool prepared = true;        // false: `prepare` failed and the work did not run
};

struct ChildLimits {
  double seconds = 600;              // the child is killed past this, and the run throws
  std::uint64_t address_space = 0;   // RLIMIT_AS of the child, 0 for none
};

// Forks; the child runs `prepare` (not measured; "" when it succeeded, else why not), resets the
// peak, runs `work` and reports what it returned. Throws std::runtime_error naming `what` when
// the child dies, is killed by a signal, cannot reset its peak, or outlives the limit.
ChildPeak peak_in_child(const std::string& what, const std::function<std::string()>& prepare,
                        const std::function<std::string()>& work, const ChildLimits& limits = {});

}  // namespace softdeca::cli
