#include "recording/timecode.h"

#include <cmath>
#include <cstdint>
#include <cstdio>

namespace softdeca::recording {
namespace {
// Reads 1 to `max_digits` decimal digits.
bool digits(std::string_view& s, int max_digits, long& out) {
  out = 0;
  int n = 0;
  while (!s.empty() && n < max_digits && s.front() >= '0' && s.front() <= '9') {
    out = out * 10 + (s.front() - '0');
    s.remove_prefix(1);
    ++n;
  }
  return n > 0;
}
bool expect(std::string_view& s, char c) {
  if (s.empty() || s.front() != c) return false;
  s.remove_prefix(1);
  return true;
}
}  // namespace

bool parse_timecode(std::string_view s, double rate, double& seconds) {
  long h = 0, m = 0, sec = 0, frame = 0, milli = 0;
  if (!(rate > 0 && rate <= 1000)) return false;
  if (!digits(s, 2, h) || !expect(s, ':') || !digits(s, 2, m) || !expect(s, ':') ||
      !digits(s, 2, sec) || !expect(s, ':') || !digits(s, 4, frame))
    return false;
  double subframe = 0;
  if (!s.empty()) {
    const std::size_t before = s.size();
    if (!expect(s, '.') || !digits(s, 3, milli) || !s.empty()) return false;
    subframe = milli / std::pow(10.0, static_cast<double>(before - 1));
  }
  if (h >= 24 || m >= 60 || sec >= 60 || frame >= std::ceil(rate)) return false;
  seconds = static_cast<double>(h * 3600 + m * 60 + sec) + (static_cast<double>(frame) + subframe) / rate;
  return true;
}

std::string format_timecode(double seconds, int rate) {
  // Whole thousandths of a frame, so that rounding carries into the frame and second fields.
  const auto thousandths = static_cast<int64_t>(std::llround(seconds * rate * 1000.0));
  const int64_t frames = thousandths / 1000;
  const int64_t whole_seconds = frames / rate;
  char buf[48];
  std::snprintf(buf, sizeof buf, "%02lld:%02lld:%02lld:%02lld.%03lld",
                static_cast<long long>(whole_seconds / 3600 % 24), static_cast<long long>(whole_seconds / 60 % 60),
                static_cast<long long>(whole_seconds % 60), static_cast<long long>(frames % rate),
                static_cast<long long>(thousandths % 1000));
  return buf;
}

}  // namespace softdeca::recording
