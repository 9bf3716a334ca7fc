// The options of the commands that fit a user's avatar (fit, and replay of an avatar fitted on
// the spot): the rig-name mapping file and the fit's own options.
#pragma once

#include "fit/limits.h"
#include "imported_avatar.h"
#include "options.h"
#include "runtime_session.h"

namespace softdeca::cli {

inline void declare_fit_options(Options& o) {
  o.option("--names", "FILE", "lines 'rigName<TAB>arkitName' or 'rigName=arkitName' ('none' leaves a shape out); "
                              "the names listed override the rule")
      .option("--metres-per-unit", "X", "the mesh's unit in metres, 1e-6 to 1000 (0: read off the shapes)", "0")
      .option("--iterations", "N", "registration iterations (0: the library's default)", "0");
}

inline ShapeNames shape_names(const Options& o) {
  return o.given("--names") ? ShapeNames::from_file(o.text("--names")) : ShapeNames();
}

inline softdeca_fit_options fit_options(const Options& o) {
  const double metres_per_unit = o.number("--metres-per-unit");
  const long iterations = o.integer("--iterations");
  if (iterations < 0) throw UsageError("--iterations must not be negative");
  // The range a saved fit's unit is read back in: a fit made with any other unit would not load.
  if (metres_per_unit != 0 && !(metres_per_unit >= fit::kMinMetresPerUnit && metres_per_unit <= fit::kMaxMetresPerUnit))
    throw UsageError("--metres-per-unit must be 0 (read off the shapes) or " + fit::metres_per_unit_range() +
                     " (metres), not " + o.text("--metres-per-unit"));
  softdeca_fit_options options{};
  options.struct_size = sizeof options;
  check(softdeca_fit_options_init(&options), "fit options");
  options.metres_per_unit = metres_per_unit;
  if (iterations > 0) options.iterations = static_cast<uint32_t>(iterations);
  return options;
}

}  // namespace softdeca::cli
