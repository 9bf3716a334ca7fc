// Shared by the bench-* commands: their output options, one benchmark figure as JSON, and how
// busy the machine was.
#pragma once

#include <string>

#include "options.h"

namespace softdeca::cli {

// {"value", "unit", "target" (JSON text), "better", "how"}.
std::string figure(double value, const char* unit, const std::string& target, const char* better, const std::string& how);

// The --out (the benchmark JSON, default build/bench/<area>.json) and --scratch (where the runs
// write their files, default build/bench) options of a bench-* command that writes files.
void declare_output_options(Options& o, const std::string& area, const std::string& scratch_help);
// After parsing: creates the JSON's folder and the scratch folder; returns the scratch folder.
std::string create_output_folders(const Options& o);

// The 1-minute load average (Linux; -1 elsewhere), to tell the reader how busy the machine was.
double load_average();

}  // namespace softdeca::cli
