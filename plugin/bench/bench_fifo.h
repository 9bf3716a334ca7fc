// bench-reliability's FIFO run: every path that opens a recording or a CSV take, handed a FIFO
// with nobody at its other end, and how long each takes to refuse it (docs/security.md).
#pragma once

#include <string>

namespace softdeca::cli {

struct FifoRefusal {
  double worst_ms = 0;    // the slowest path's refusal
  std::string worst;      // which path that was
  int paths = 0;
};

// FIFOs are made under `scratch` and removed. Throws std::runtime_error when a path accepts a
// FIFO or has not returned after 5 s (the FIFO is then opened from the other end to free it).
FifoRefusal fifo_refusal_run(const std::string& scratch);

}  // namespace softdeca::cli
