// Numbers in recordings and takes: the CSV writer's text reads back as the very floats it was
// written from; CSV files with any line ending read alike; one rule for out-of-range values
// (recording/frame_rule.h) in the reader, the player and CSV takes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <random>
#include <string>
#include <vector>

#include "recording/livelinkface_csv.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "softdeca/softdeca.h"
#include "stream/livelinkface_layout.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::recording;

namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t begin = 0;
  for (std::size_t comma; (comma = line.find(',', begin)) != std::string::npos; begin = comma + 1)
    out.push_back(line.substr(begin, comma - begin));
  out.push_back(line.substr(begin));
  return out;
}

uint32_t bits(float v) {
  uint32_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// Weights over the whole positive float range: the smallest subnormal, the smallest normal,
// fractions, 1, 1e30, the largest float, and random bit patterns between them.
std::vector<float> hard_values() {
  std::vector<float> v = {1e-45f, 1.17549435e-38f, 1e-10f, 0.1f, 1.0f / 3, 0.99999994f, 1.0f, 1e30f, 3.4028235e38f};
  std::mt19937 rng(7);
  std::uniform_int_distribution<uint32_t> pattern(1, 0x7f7fffffu);
  while (v.size() < 52 * 20) {
    const uint32_t b = pattern(rng);
    float f = 0;
    std::memcpy(&f, &b, sizeof f);
    v.push_back(f);
  }
  return v;
}

TEST(CsvNumbers, EveryWrittenFloatReadsBackExactly) {
  const std::vector<float> values = hard_values();
  std::vector<stream::Frame> frames;
  for (std::size_t at = 0; at < values.size(); at += 52) {
    stream::Frame f;
    f.capture_time = 3600 + double(frames.size()) / 60;
    for (std::size_t k = 0; k < 52; ++k) f.weights[k] = values[at + k];
    frames.push_back(f);
  }
  const std::string csv = format_livelinkface_csv(frames, 60);
  std::vector<std::string> lines;
  for (std::size_t begin = 0, end; (end = csv.find('\n', begin)) != std::string::npos; begin = end + 1)
    lines.push_back(csv.substr(begin, end - begin));
  ASSERT_EQ(lines.size(), frames.size() + 1);
  const std::vector<std::string> header = split(lines[0]);
  for (std::size_t row = 0; row < frames.size(); ++row) {
    const std::vector<std::string> fields = split(lines[row + 1]);
    ASSERT_EQ(fields.size(), header.size());
    for (std::size_t i = 0; i < 52; ++i) {
      const std::size_t column = 2 + i;
      std::size_t value = 0;
      while (value < stream::livelinkface::kValueCount && header[column] != stream::livelinkface::value_name(value)) ++value;
      const float expected = frames[row].weights[static_cast<std::size_t>(stream::livelinkface::canonical_index(value))];
      const float got = std::strtof(fields[column].c_str(), nullptr);
      EXPECT_EQ(bits(got), bits(expected)) << header[column] << " = " << expected << " written as " << fields[column];
    }
  }
}

TEST(CsvNumbers, WeightsInRangeSurviveAFileRoundTrip) {
  std::vector<stream::Frame> frames(1);
  frames[0].capture_time = 7200;
  for (std::size_t k = 0; k < 52; ++k) frames[0].weights[k] = k == 0 ? 1e-45f : 1.0f / float(k + 1);
  const std::string path = test::temp_path("numbers.csv");
  write_livelinkface_csv(path, frames, 60);
  const CsvTake take = read_livelinkface_csv(path, 60);
  ASSERT_EQ(take.frames.size(), 1u);
  for (std::size_t k = 0; k < 52; ++k) EXPECT_EQ(bits(take.frames[0].weights[k]), bits(frames[0].weights[k])) << k;
  std::remove(path.c_str());
}

}  // namespace

namespace {

// The same take with LF, CRLF and CR-only line endings reads to the same frames.
TEST(CsvLines, EveryLineEndingReadsTheSameFrames) {
  std::vector<stream::Frame> frames(3);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    frames[i].capture_time = 3600 + double(i) / 60;
    frames[i].weights[i] = 0.5f;
  }
  const std::string lf = format_livelinkface_csv(frames, 60);
  std::string crlf, cr;
  for (char c : lf) {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    cr += c == '\n' ? '\r' : c;
  }
  for (const std::string* text : std::initializer_list<const std::string*>{&lf, &crlf, &cr}) {
    const CsvTake take = parse_livelinkface_csv(*text, 60);
    ASSERT_EQ(take.frames.size(), 3u);
    EXPECT_EQ(take.malformed_rows, 0u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(take.frames[i].weights[i], 0.5f);
  }
}

}  // namespace

namespace {

// Frames a recording may hold: good, weights far out of range, a NaN weight, a zero rotation, a
// landmark 1e30 m away. The reader keeps the first two (the second clamped) and counts the rest.
TEST(FrameRule, TheReaderAndThePlayerClampOrLeaveOutAndCount) {
  const std::string path = test::temp_path("values.sdrec");
  {
    RecordingWriter w(path, Header{});
    stream::Frame good = test::make_frame(1, 0, 0);
    good.weights.fill(0.25f);
    w.write(good);
    stream::Frame wild = good;
    wild.capture_time += 0.1;
    wild.weights[0] = 1e30f;
    wild.weights[1] = -1e30f;
    w.write(wild);
    stream::Frame nan = good;
    nan.weights[2] = std::nanf("");
    w.write(nan);
    stream::Frame zero = good;
    zero.has_head = true;
    zero.head.rotation = {0, 0, 0, 0};
    w.write(zero);
    stream::Frame far = good;
    far.landmark_count = 1;
    far.landmarks[0] = 1e30f;
    w.write(far);
  }
  const Recording rec = read_recording(path);
  ASSERT_EQ(rec.frames.size(), 2u);
  EXPECT_EQ(rec.recovery.invalid_frames, 3u);
  EXPECT_EQ(rec.recovery.clamped_frames, 1u);
  EXPECT_EQ(rec.recovery.damaged_regions, 0u);
  EXPECT_EQ(rec.frames[1].weights[0], 1.0f);
  EXPECT_EQ(rec.frames[1].weights[1], 0.0f);

  softdeca_player* player = nullptr;
  ASSERT_EQ(softdeca_player_load(path.c_str(), &player), SOFTDECA_OK) << softdeca_last_error();
  for (uint32_t i = 0; i < 2; ++i) {
    softdeca_frame f{};
    f.struct_size = sizeof f;
    ASSERT_EQ(softdeca_player_get_frame(player, i, &f), SOFTDECA_OK);
    for (float w : f.weights) EXPECT_TRUE(w >= 0 && w <= 1) << w;
  }
  softdeca_player_destroy(player);
  std::remove(path.c_str());
}

// A take's rows under the same rule: a weight of 5 is clamped and counted, a head angle of 1e30
// radians (no rotation a tracker measured) leaves the row out as malformed.
TEST(FrameRule, CsvTakesFollowTheSameRule) {
  std::vector<stream::Frame> frames(3);
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i].capture_time = 3600 + double(i) / 60;
  std::string csv = format_livelinkface_csv(frames, 60);
  const std::string header = csv.substr(0, csv.find('\n'));
  std::vector<std::string> rows;
  for (std::size_t begin = header.size() + 1, end; (end = csv.find('\n', begin)) != std::string::npos; begin = end + 1)
    rows.push_back(csv.substr(begin, end - begin));
  ASSERT_EQ(rows.size(), 3u);
  const std::vector<std::string> names = split(header);
  std::size_t yaw = 0, blink = 0;
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (names[c] == "HeadYaw") yaw = c;
    if (names[c] == "EyeBlinkLeft") blink = c;
  }
  ASSERT_GT(yaw, 0u);
  ASSERT_GT(blink, 0u);
  const auto with = [&](const std::string& row, std::size_t column, const std::string& value) {
    std::vector<std::string> fields = split(row);
    fields[column] = value;
    std::string out;
    for (std::size_t c = 0; c < fields.size(); ++c) out += (c ? "," : "") + fields[c];
    return out;
  };
  const std::string text = header + "\n" + rows[0] + "\n" + with(rows[1], blink, "5") + "\n" + with(rows[2], yaw, "1e30") + "\n";
  const CsvTake take = parse_livelinkface_csv(text, 60);
  ASSERT_EQ(take.frames.size(), 2u);
  EXPECT_EQ(take.clamped_rows, 1u);
  EXPECT_EQ(take.malformed_rows, 1u);
  for (const stream::Frame& f : take.frames)
    for (float w : f.weights) EXPECT_TRUE(w >= 0 && w <= 1) << w;
}

}  // namespace
