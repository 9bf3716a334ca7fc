// One material parameter as the library describes it, in both of its lists: the physics'
// (plugin/data/parameters.json compiled in, sim/parameters.h) and a bundle's (its manifest,
// bundle/manifest.h). The C ABI's softdeca_parameter_info, the Python package's ParameterSpec
// and Unity's ParameterInfo carry the same fields under the same names.
#pragma once

#include <string>

namespace softdeca {

struct ParameterSpec {
  std::string name;
  std::string symbol;  // the paper's symbol
  std::string unit;    // "kPa", "g", "deg" or ""
  std::string domain;  // "global" or the element kind per-element values are given for
  std::string description;
  double default_value = 0, minimum = 0, maximum = 0;  // the closed range [minimum, maximum]
  bool log_scale = false;                              // sampled uniformly in log space
  bool localisable = false;                            // per-face / per-vertex maps are accepted
};

}  // namespace softdeca
