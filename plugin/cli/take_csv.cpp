#include "take_csv.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "runtime/manifest.h"

namespace softdeca::cli {

namespace {
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    std::string field = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    while (!field.empty() && (field.back() == '\r' || field.back() == ' ')) field.pop_back();
    out.push_back(field);
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

// "HH:MM:SS:FF.fff" on a 60 fps timecode clock -> seconds; NaN when unreadable.
double timecode_seconds(const std::string& t) {
  int h = 0, m = 0, s = 0;
  double frames = 0;
  char* end = nullptr;
  const char* p = t.c_str();
  h = static_cast<int>(std::strtol(p, &end, 10));
  if (*end != ':') return std::nan("");
  m = static_cast<int>(std::strtol(end + 1, &end, 10));
  if (*end != ':') return std::nan("");
  s = static_cast<int>(std::strtol(end + 1, &end, 10));
  if (*end != ':') return std::nan("");
  frames = std::strtod(end + 1, &end);
  return h * 3600.0 + m * 60.0 + s + frames / 60.0;
}
}  // namespace

Take read_livelinkface_csv(const std::string& path, std::size_t max_frames) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty file");
  const auto header = split(line);
  const auto find = [&](const std::string& name) -> int {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  };
  if (find("BlendShapeCount") < 0 && find("BlendshapeCount") < 0)
    throw std::runtime_error(path + ": not a Live Link Face CSV (no BlendShapeCount column)");
  const int time_col = find("Timecode");
  std::array<int, 52> col{};
  for (int i = 0; i < 52; ++i) {
    std::string name = runtime::kArkitBlendshapes[i];
    name[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(name[0])));
    col[static_cast<std::size_t>(i)] = find(name);
    if (col[static_cast<std::size_t>(i)] < 0) throw std::runtime_error(path + ": no column " + name);
  }
  Take take;
  take.path = path;
  while (std::getline(in, line)) {
    if (line.empty() || line == "\r") continue;
    ++take.rows;
    const auto f = split(line);
    if (f.size() < header.size()) {  // the app writes only the timecode and count when the face is lost
      ++take.face_lost;
      continue;
    }
    std::array<float, 52> w{};
    bool ok = true;
    for (std::size_t i = 0; i < 52 && ok; ++i) {
      char* end = nullptr;
      const std::string& v = f[static_cast<std::size_t>(col[i])];
      const float x = std::strtof(v.c_str(), &end);
      ok = end != v.c_str() && std::isfinite(x);
      w[i] = std::min(1.0f, std::max(0.0f, x));
    }
    if (!ok) {
      ++take.invalid;
      continue;
    }
    take.weights.push_back(w);
    take.seconds.push_back(time_col >= 0 ? timecode_seconds(f[static_cast<std::size_t>(time_col)]) : std::nan(""));
    if (max_frames && take.weights.size() >= max_frames) break;
  }
  if (take.weights.empty()) throw std::runtime_error(path + ": no usable frame");
  std::vector<double> dt;
  for (std::size_t i = 1; i < take.seconds.size(); ++i)
    if (std::isfinite(take.seconds[i] - take.seconds[i - 1]) && take.seconds[i] > take.seconds[i - 1])
      dt.push_back(take.seconds[i] - take.seconds[i - 1]);
  if (!dt.empty()) {
    std::nth_element(dt.begin(), dt.begin() + static_cast<long>(dt.size() / 2), dt.end());
    take.median_frame_s = dt[dt.size() / 2];
  }
  return take;
}

}  // namespace softdeca::cli
