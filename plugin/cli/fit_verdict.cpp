#include "fit_verdict.h"

#include <cstdio>

#include "bundle/json.h"

namespace softdeca::cli {

Verdict read_verdict(const std::string& report) {
  const bundle::Json r = bundle::Json::parse(report);
  const bundle::Json& q = r.at("quality", "the fit's report");
  const auto number = [&](const char* name) { return r.at(name, "the fit's report").number(name); };
  char scale[32] = "not measured";
  if (!r.at("template_scale", "the fit's report").is_null()) std::snprintf(scale, sizeof scale, "%.2f", number("template_scale"));
  std::fprintf(stderr,
               "the template covers %.0f %% of the face (within %g mm); the face lies %.2f mm (median) and %.2f mm (90th "
               "percentile) from it; template face size / avatar's: %s\n",
               100 * number("face_coverage"), q.at("bounds", "quality").at("covered_mm", "bounds").number("covered_mm"),
               number("avatar_to_template_mm_median"), number("avatar_to_template_mm_p90"), scale);
  Verdict v;
  v.passed = q.at("passed", "quality").boolean("quality.passed");
  v.measure = q.at("failed_measure", "quality").string("quality.failed_measure");
  v.reason = q.at("reason", "quality").string("quality.reason");
  return v;
}

}  // namespace softdeca::cli
