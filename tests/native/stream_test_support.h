// Shared by the streaming tests: paths to the golden files and the third-party data, the golden files'
// expected-values format (tests/golden/streaming/README.md), and frames to play with.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "stream/frame.h"
#include "stream/rotation.h"

namespace softdeca::test {

// Polls `done` for up to 10 s (generous for a loaded machine); true once it holds.
inline bool eventually(const std::function<bool()>& done) {
  for (int i = 0; i < 2000; ++i) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return done();
}

inline std::string golden_dir() { return std::string(SOFTDECA_REPO_ROOT) + "/tests/golden/streaming/"; }
// The data folder `make setup` fills; $SOFTDECA_DATA overrides the configured one.
inline std::string data_dir() {
  const char* env = std::getenv("SOFTDECA_DATA");
  return std::string(env && *env ? env : SOFTDECA_DATA_DIR) + "/";
}
inline std::string takes_dir() { return data_dir() + "recordings/livelinkface-alexdjulin/"; }

// A file name in the test's temporary folder, unique to this process.
inline std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "softdeca-" + std::to_string(::getpid()) + "-" + name;
}

inline std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Sections ("" before the first "[name]") of key -> the rest of the line.
using Section = std::map<std::string, std::string>;
inline std::map<std::string, Section> read_expected(const std::string& path) {
  std::map<std::string, Section> sections;
  std::ifstream in(path);
  std::string line, current;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (line.front() == '[' && line.back() == ']') {
      current = line.substr(1, line.size() - 2);
      continue;
    }
    const std::size_t space = line.find(' ');
    sections[current][line.substr(0, space)] = space == std::string::npos ? "" : line.substr(space + 1);
  }
  return sections;
}

inline std::vector<double> numbers(const Section& s, const std::string& key) {
  std::vector<double> out;
  const auto it = s.find(key);
  if (it == s.end()) return out;
  std::istringstream in(it->second);
  std::string token;
  while (in >> token) out.push_back(std::stod(token));
  return out;
}

// A deterministic, plausible frame: weights in [0, 1], poses, `landmarks` points in a face box.
inline stream::Frame make_frame(uint32_t i, uint16_t landmarks = 0, uint32_t profile_id = 0) {
  stream::Frame f;
  f.capture_time = 100.0 + i / 60.0;
  for (std::size_t k = 0; k < f.weights.size(); ++k)
    f.weights[k] = static_cast<float>(0.5 + 0.5 * std::sin(0.37 * double(i) + double(k)));
  f.has_head = f.has_eyes = true;
  f.head.position = {0.01f, -0.02f * float(i % 7), -0.45f};
  f.head.rotation = stream::quaternion_from_yaw_pitch_roll(0.01 * i, -0.1, 0.02);
  f.left_eye.rotation = stream::quaternion_from_yaw_pitch_roll(0.1, 0.05 * std::sin(double(i)), 0);
  f.right_eye.rotation = stream::quaternion_from_yaw_pitch_roll(0.1, -0.05, 0);
  f.landmark_count = landmarks;
  f.profile_id = profile_id;
  for (std::size_t k = 0; k < 3u * landmarks; ++k)
    f.landmarks[k] = static_cast<float>(0.09 * std::sin(0.7 * double(k) + 0.1 * double(i)));
  return f;
}

}  // namespace softdeca::test
