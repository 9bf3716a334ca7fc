// The library's verdict on a fit (its report's "quality"): the command line refuses a poor fit
// where it makes one (softdeca fit, softdeca replay of a mesh fitted on the spot) and says so
// where it uses one kept with --keep-poor-fit.
#pragma once

#include <string>

namespace softdeca::cli {

struct Verdict {
  bool passed = true;
  std::string measure, reason;
};

// The verdict of softdeca_avatar_fit_get_report's JSON; the measures are printed on stderr.
Verdict read_verdict(const std::string& report);

}  // namespace softdeca::cli
