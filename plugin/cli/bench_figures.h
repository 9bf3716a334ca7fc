// Shared by the bench-* commands: one benchmark figure as JSON, and how busy the machine was.
#pragma once

#include <string>

namespace softdeca::cli {

// {"value", "unit", "target" (JSON text), "better", "how"}.
std::string figure(double value, const char* unit, const std::string& target, const char* better, const std::string& how);

// Creates the folder of the JSON output file and the scratch folder.
void create_output_folders(const std::string& out_file, const std::string& scratch);

// The 1-minute load average (Linux; -1 elsewhere), to tell the reader how busy the machine was.
double load_average();

}  // namespace softdeca::cli
