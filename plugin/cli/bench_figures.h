// Shared by the bench-* commands: one benchmark figure as JSON, and how busy the machine was.
#pragma once

#include <string>

namespace softdeca::cli {

// {"value", "unit", "target" (JSON text), "better", "how"}.
std::string figure(double value, const char* unit, const std::string& target, const char* better, const std::string& how);

// The 1-minute load average (Linux; -1 elsewhere), to tell the reader how busy the machine was.
double load_average();

}  // namespace softdeca::cli
