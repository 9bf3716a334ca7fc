#include "json.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/regular_file.h"

namespace softdeca::cli {

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

namespace {
std::string format(double v, const char* spec) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}
}  // namespace

// 17 significant digits give a double back exactly, 9 a float.
std::string json_number(double v) { return format(v, "%.17g"); }

std::string json_array(const float* values, std::size_t count) {
  std::string out = "[";
  for (std::size_t i = 0; i < count; ++i) out += (i ? "," : "") + format(values[i], "%.9g");
  return out + "]";
}

JsonObject& JsonObject::raw(const std::string& key, std::string json) {
  members_.emplace_back(key, std::move(json));
  return *this;
}

std::string JsonObject::str(bool pretty) const {
  std::string out = "{";
  for (std::size_t i = 0; i < members_.size(); ++i) {
    out += i ? "," : "";
    if (pretty) out += "\n  ";
    out += json_string(members_[i].first) + (pretty ? ": " : ":") + members_[i].second;
  }
  return out + (pretty ? "\n}" : "}");
}

// Through the library's one way of opening files (a FIFO given to --stats-json is refused, not
// waited on).
void write_text_file(const std::string& path, const std::string& text) {
  const FilePtr out = open_regular_file(path, FileAccess::create);
  if (std::fwrite(text.data(), 1, text.size(), out.get()) != text.size() || std::fflush(out.get()) != 0)
    throw std::runtime_error("cannot write " + path);
}

}  // namespace softdeca::cli
