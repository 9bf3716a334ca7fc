// The --frames and --duration limits of the commands that run until told to stop (play,
// receive): after N frames, or after so many seconds of wall-clock time; 0 is no limit.
#pragma once

#include <cmath>
#include <string>

#include "options.h"

namespace softdeca::cli {

struct StopLimits {
  long frames = 0;
  double seconds = 0;

  // Declares both options; `frames_help` says which frames count ("stop after N <frames_help>").
  static void declare(Options& o, const std::string& frames_help) {
    o.option("--frames", "N", "stop after N " + frames_help + " (0: no limit)", "0")
        .option("--duration", "SECONDS", "stop after this much wall-clock time (0: no limit)", "0");
  }
  static StopLimits read(const Options& o) {
    const StopLimits s{o.integer("--frames"), o.number("--duration")};
    if (s.frames < 0 || !(s.seconds >= 0) || !std::isfinite(s.seconds))
      throw UsageError("--frames and --duration must be 0 (no limit) or positive");
    return s;
  }
  bool reached(double frames_done, double seconds_elapsed) const {
    return (frames > 0 && frames_done >= double(frames)) || (seconds > 0 && seconds_elapsed >= seconds);
  }
};

}  // namespace softdeca::cli
