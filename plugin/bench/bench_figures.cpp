#include "bench_figures.h"

#include <filesystem>
#include <fstream>

#include "json.h"

namespace softdeca::cli {

std::string figure(double value, const char* unit, const std::string& target, const char* better, const std::string& how) {
  return JsonObject().number("value", value).text("unit", unit).raw("target", target).text("better", better)
      .text("how", how).str();
}

void declare_output_options(Options& o, const std::string& area, const std::string& scratch_help) {
  o.option("--out", "FILE", "JSON output", "build/bench/" + area + ".json")
      .option("--scratch", "DIR", scratch_help, "build/bench");
}

std::string create_output_folders(const Options& o) {
  const std::string scratch = o.text("--scratch");
  for (const std::string& dir : {std::filesystem::path(o.text("--out")).parent_path().string(), scratch})
    if (!dir.empty()) std::filesystem::create_directories(dir);
  return scratch;
}

double load_average() {
  std::ifstream in("/proc/loadavg");
  double load = -1;
  in >> load;
  return load;
}

}  // namespace softdeca::cli
