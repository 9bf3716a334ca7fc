#include "bench_figures.h"

#include <fstream>

#include "json.h"

namespace softdeca::cli {

std::string figure(double value, const char* unit, const std::string& target, const char* better, const std::string& how) {
  return JsonObject().number("value", value).text("unit", unit).raw("target", target).text("better", better)
      .text("how", how).str();
}

double load_average() {
  std::ifstream in("/proc/loadavg");
  double load = -1;
  in >> load;
  return load;
}

}  // namespace softdeca::cli
