// Just enough JSON output for the CLI: statistics, frames as JSON lines, benchmark figures.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace softdeca::cli {

std::string json_string(const std::string& text);
std::string json_number(double value);  // null for NaN and infinities
std::string json_array(const float* values, std::size_t count);

// Keys in insertion order; values are already JSON.
class JsonObject {
 public:
  JsonObject& raw(const std::string& key, std::string json);
  JsonObject& number(const std::string& key, double value) { return raw(key, json_number(value)); }
  JsonObject& text(const std::string& key, const std::string& value) { return raw(key, json_string(value)); }
  std::string str(bool pretty = false) const;

 private:
  std::vector<std::pair<std::string, std::string>> members_;
};

// Writes text to a file; throws std::runtime_error when it cannot.
void write_text_file(const std::string& path, const std::string& text);

}  // namespace softdeca::cli
