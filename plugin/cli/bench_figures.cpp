#include "bench_figures.h"

#include <filesystem>
#include <fstream>

#include "json.h"

namespace softdeca::cli {

std::string figure(double value, const char* unit, const std::string& target, const char* better, const std::string& how) {
  return JsonObject().number("value", value).text("unit", unit).raw("target", target).text("better", better)
      .text("how", how).str();
}

void create_output_folders(const std::string& out_file, const std::string& scratch) {
  for (const std::string& dir : {std::filesystem::path(out_file).parent_path().string(), scratch})
    if (!dir.empty()) std::filesystem::create_directories(dir);
}

double load_average() {
  std::ifstream in("/proc/loadavg");
  double load = -1;
  in >> load;
  return load;
}

}  // namespace softdeca::cli
