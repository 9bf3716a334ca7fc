// Recordings: write and read back exactly; a file cut anywhere loses at most its last frame; a
// damaged record costs only itself; a damaged header is refused; and the player's seeking,
// looping, speed and interpolation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/error.h"
#include "recording/conversions.h"
#include "recording/frame_interpolation.h"
#include "recording/livelinkface_csv.h"
#include "recording/player.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::recording;
using stream::Frame;
using test::make_frame;
using test::temp_path;

namespace {

stream::wire::Profile profile() {
  stream::wire::Profile p;
  p.name = "test";
  p.indices = {3, 1, 4, 15, 9, 26};
  p.id = stream::wire::profile_id_of(p.indices);
  return p;
}

// A recording of n frames with landmarks; returns its bytes and where each record ends.
std::vector<uint8_t> write_sample(const std::string& path, std::size_t n, std::vector<std::size_t>* ends = nullptr) {
  Header h;
  h.device = "test device";
  h.subject = "take 1";
  h.start_unix_time = 1.7e9;
  h.has_profile = true;
  h.profile = profile();
  {
    RecordingWriter w(path, h);
    for (std::size_t i = 0; i < n; ++i) {
      Frame f = make_frame(static_cast<uint32_t>(i), 6, h.profile.id);
      f.session_id = 5;
      f.sequence = static_cast<uint32_t>(i);
      f.has_sequence = true;
      w.write(f);
      if (ends) {
        std::FILE* file = std::fopen(path.c_str(), "rb");
        std::fseek(file, 0, SEEK_END);
        ends->push_back(static_cast<std::size_t>(std::ftell(file)));
        std::fclose(file);
      }
    }
    EXPECT_EQ(w.frames_written(), n);
  }
  return test::read_bytes(path);
}

void expect_same(const Frame& a, const Frame& b) {
  EXPECT_EQ(a.capture_time, b.capture_time);
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.weights, b.weights);
  EXPECT_EQ(a.has_head, b.has_head);
  EXPECT_EQ(a.head.rotation, b.head.rotation);
  EXPECT_EQ(a.left_eye.rotation, b.left_eye.rotation);
  EXPECT_EQ(a.landmark_count, b.landmark_count);
  EXPECT_EQ(a.landmarks, b.landmarks);
}

}  // namespace

TEST(Recording, RoundTripsExactly) {
  const std::string path = temp_path("roundtrip.sdrec");
  write_sample(path, 20);
  const Recording rec = read_recording(path);
  EXPECT_EQ(rec.header.device, "test device");
  EXPECT_EQ(rec.header.subject, "take 1");
  EXPECT_EQ(rec.header.start_unix_time, 1.7e9);
  EXPECT_EQ(rec.header.units, "m");
  ASSERT_EQ(rec.profiles.size(), 1u);
  EXPECT_EQ(rec.profiles[0].indices, profile().indices);
  ASSERT_EQ(rec.frames.size(), 20u);
  for (std::size_t i = 0; i < 20; ++i) {
    Frame want = make_frame(static_cast<uint32_t>(i), 6, profile().id);
    want.sequence = static_cast<uint32_t>(i);
    expect_same(rec.frames[i], want);
  }
  EXPECT_EQ(rec.recovery.records, 20u);
  std::remove(path.c_str());
}

TEST(Recording, AFileCutAnywhereLosesAtMostItsLastFrame) {
  const std::string path = temp_path("cut.sdrec");
  std::vector<std::size_t> ends;
  const auto bytes = write_sample(path, 8, &ends);
  const std::size_t header_end = ends[0] - (ends[1] - ends[0]);
  for (std::size_t cut = header_end; cut <= bytes.size(); ++cut) {
    const Recording rec = parse_recording(bytes.data(), cut);
    std::size_t complete = 0;
    while (complete < ends.size() && ends[complete] <= cut) ++complete;
    ASSERT_EQ(rec.frames.size(), complete) << "cut at " << cut;
    EXPECT_EQ(rec.recovery.truncated_bytes, cut - (complete ? ends[complete - 1] : header_end));
    EXPECT_EQ(rec.recovery.damaged_regions, 0u);
    for (std::size_t i = 0; i < complete; ++i) EXPECT_EQ(rec.frames[i].sequence, i);
  }
  // Within the header there is nothing to trust.
  for (std::size_t cut : {std::size_t{0}, std::size_t{7}, std::size_t{20}, header_end - 1})
    EXPECT_THROW(parse_recording(bytes.data(), cut), Error) << cut;
  std::remove(path.c_str());
}

TEST(Recording, ADamagedRecordCostsOnlyItself) {
  const std::string path = temp_path("damaged.sdrec");
  std::vector<std::size_t> ends;
  const auto clean = write_sample(path, 10, &ends);
  // Flip a byte inside record 4's payload, its length, its checksum, and its magic in turn.
  const std::size_t start = ends[3];
  for (std::size_t offset : {std::size_t{0}, std::size_t{5}, std::size_t{9}, std::size_t{40}, ends[4] - start - 1}) {
    SCOPED_TRACE(offset);
    auto bytes = clean;
    bytes[start + offset] ^= 0x10;
    const Recording rec = parse_recording(bytes.data(), bytes.size());
    ASSERT_EQ(rec.frames.size(), 9u);
    EXPECT_EQ(rec.recovery.damaged_regions, 1u);
    EXPECT_EQ(rec.recovery.skipped_bytes, ends[4] - start);
    for (std::size_t i = 0; i < 9; ++i) EXPECT_EQ(rec.frames[i].sequence, i < 4 ? i : i + 1);
  }
  // Garbage spliced between two records is skipped too.
  auto spliced = clean;
  spliced.insert(spliced.begin() + static_cast<std::ptrdiff_t>(ends[5]), {'S', 'D', 'R', 'C', 9, 9, 9});
  const Recording rec = parse_recording(spliced.data(), spliced.size());
  EXPECT_EQ(rec.frames.size(), 10u);
  EXPECT_EQ(rec.recovery.skipped_bytes, 7u);
  std::remove(path.c_str());
}

TEST(Recording, ADamagedOrForeignHeaderIsRefusedClearly) {
  const std::string path = temp_path("header.sdrec");
  auto bytes = write_sample(path, 2);
  auto bad = bytes;
  bad[30] ^= 1;  // inside the header fields: the header checksum fails
  EXPECT_THROW(parse_recording(bad.data(), bad.size()), Error);
  bad = bytes;
  bad[8] = 2;  // format version 2.0
  try {
    parse_recording(bad.data(), bad.size());
    FAIL() << "a 2.0 file was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), SOFTDECA_ERROR_FORMAT);
    EXPECT_NE(std::string(e.what()).find("2.0"), std::string::npos) << e.what();
  }
  bad = bytes;
  bad[1] = 'X';
  EXPECT_THROW(parse_recording(bad.data(), bad.size()), Error);
  EXPECT_THROW(read_recording(temp_path("does-not-exist.sdrec")), Error);
  std::remove(path.c_str());
}

TEST(Recording, WriterRefusesAnInvalidProfileBeforeCreatingTheFile) {
  Header h;
  h.has_profile = true;
  h.profile = profile();
  h.profile.id ^= 1;
  const std::string path = temp_path("refused.sdrec");
  EXPECT_THROW(RecordingWriter(path, h), Error);
  EXPECT_EQ(std::fopen(path.c_str(), "rb"), nullptr);
  EXPECT_THROW(RecordingWriter("/nonexistent-dir/x.sdrec", Header{}), Error);
}

TEST(Recording, LiveLinkFaceCsvConvertsBothWays) {
  const std::string rec_path = temp_path("s88.sdrec"), csv_path = temp_path("s88.csv");
  const auto r = csv_to_recording(test::takes_dir() + "S88-001.csv", rec_path, 0);
  EXPECT_EQ(r.rows, 1939u);
  EXPECT_EQ(r.face_lost_rows, 277u);
  EXPECT_EQ(r.frames, 1662u);
  const Recording rec = read_recording(rec_path);
  EXPECT_EQ(rec.header.subject, "S88-001");
  EXPECT_EQ(rec.header.timecode_rate, 60.0);
  EXPECT_EQ(recording_to_csv(rec_path, csv_path, 0).frames, 1662u);
  const auto again = read_livelinkface_csv(csv_path, 60);
  ASSERT_EQ(again.frames.size(), 1662u);
  for (std::size_t i = 0; i < again.frames.size(); ++i) EXPECT_EQ(again.frames[i].weights, rec.frames[i].weights);
  std::remove(rec_path.c_str());
  std::remove(csv_path.c_str());
}

TEST(Interpolation, BlendsWhatCanBeBlendedAndTakesTheNearerFrameOtherwise) {
  Frame a = make_frame(0, 4, 7), b = make_frame(10, 4, 7);
  const Frame m = interpolate(a, b, 0.25);
  EXPECT_DOUBLE_EQ(m.capture_time, a.capture_time + 0.25 * (b.capture_time - a.capture_time));
  EXPECT_NEAR(m.weights[3], a.weights[3] + 0.25f * (b.weights[3] - a.weights[3]), 1e-6);
  EXPECT_NEAR(m.landmarks[5], a.landmarks[5] + 0.25f * (b.landmarks[5] - a.landmarks[5]), 1e-6);
  double n2 = 0;
  for (float c : m.head.rotation) n2 += double(c) * c;
  EXPECT_NEAR(n2, 1.0, 1e-6);
  // Slerp halfway between two yaws is the middle yaw.
  a.head.rotation = stream::quaternion_from_yaw_pitch_roll(0.2, 0, 0);
  b.head.rotation = stream::quaternion_from_yaw_pitch_roll(0.6, 0, 0);
  EXPECT_NEAR(stream::yaw_pitch_roll_from_quaternion(interpolate(a, b, 0.5).head.rotation)[0], 0.4, 1e-6);
  b.tracking = stream::Tracking::lost;
  EXPECT_EQ(interpolate(a, b, 0.4).weights, a.weights);
  EXPECT_EQ(interpolate(a, b, 0.6).tracking, stream::Tracking::lost);
  b = make_frame(10, 4, 8);  // another landmark profile: landmarks are not mixed
  EXPECT_EQ(interpolate(a, b, 0.3).landmarks, a.landmarks);
}

TEST(Player, SeeksLoopsAndPlaysAtSpeed) {
  Recording rec;
  for (uint32_t i = 0; i < 11; ++i) {
    Frame f = make_frame(i);
    f.capture_time = 500.0 + 0.1 * i;  // 1 s long, 10 Hz
    rec.frames.push_back(f);
  }
  std::swap(rec.frames[2], rec.frames[7]);  // the player sorts by capture time
  Player p(rec);
  EXPECT_EQ(p.frame_count(), 11u);
  EXPECT_NEAR(p.duration(), 1.0, 1e-12);
  EXPECT_NEAR(p.frame_time(7), 0.7, 1e-12);
  EXPECT_EQ(p.frame_at(0.3).weights, make_frame(3).weights);
  const Frame mid = p.frame_at(0.35);
  EXPECT_NEAR(mid.weights[0], 0.5f * (make_frame(3).weights[0] + make_frame(4).weights[0]), 1e-6);
  EXPECT_EQ(p.frame_at(-5).weights, make_frame(0).weights);
  EXPECT_EQ(p.frame_at(99).weights, make_frame(10).weights);

  p.seek(0.5);
  p.set_speed(2.0);
  EXPECT_FALSE(p.advance(0.1));
  EXPECT_NEAR(p.position(), 0.7, 1e-12);
  EXPECT_TRUE(p.advance(1.0));  // past the end, not looping
  EXPECT_NEAR(p.position(), 1.0, 1e-12);
  p.set_loop(true);
  p.seek(0.9);
  EXPECT_FALSE(p.advance(0.1));  // 0.9 + 0.2 wraps to 0.1
  EXPECT_NEAR(p.position(), 0.1, 1e-9);
  p.set_speed(0);
  EXPECT_FALSE(p.advance(5.0));
  EXPECT_NEAR(p.position(), 0.1, 1e-9);
  EXPECT_THROW(p.set_speed(-1), Error);
  EXPECT_THROW(p.seek(std::nan("")), Error);
  EXPECT_THROW(Player(Recording{}), Error);
}
