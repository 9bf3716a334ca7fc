// The golden packets and recording (tests/golden/streaming, written by the Python encoders):
// the C++ decoders read the expected values, and the C++ encoders reproduce the bytes.
#include <gtest/gtest.h>

#include <dirent.h>

#include <algorithm>
#include <string>
#include <vector>

#include "recording/recording_reader.h"
#include "stream/ifacialmocap_packet.h"
#include "stream/livelinkface_layout.h"
#include "stream/livelinkface_packet.h"
#include "stream/wire_format.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::stream;
using test::numbers;
using test::Section;

namespace {

std::vector<std::string> golden_packets() {
  std::vector<std::string> names;
  DIR* dir = opendir(test::golden_dir().c_str());
  if (!dir) return names;
  while (dirent* e = readdir(dir)) {
    const std::string n = e->d_name;
    if (n.size() > 4 && n.substr(n.size() - 4) == ".bin") names.push_back(n.substr(0, n.size() - 4));
  }
  closedir(dir);
  std::sort(names.begin(), names.end());
  return names;
}

void expect_floats(const std::vector<double>& want, const float* got, std::size_t n, const std::string& what) {
  ASSERT_EQ(want.size(), n) << what;
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(static_cast<float>(want[i]), got[i]) << what << "[" << i << "]";
}

void expect_pose(const Section& e, const std::string& key, bool present, const Pose& p) {
  const auto want = numbers(e, key);
  ASSERT_EQ(present, !want.empty()) << key;
  if (!present) return;
  float got[7];
  std::copy(p.position.begin(), p.position.end(), got);
  std::copy(p.rotation.begin(), p.rotation.end(), got + 3);
  expect_floats(want, got, 7, key);
}

void expect_frame(const Section& e, const Frame& f) {
  if (e.count("capture_time")) {
    EXPECT_EQ(f.capture_time, numbers(e, "capture_time")[0]);
  }
  if (e.count("send_time")) {
    EXPECT_EQ(f.send_time, numbers(e, "send_time")[0]);
  }
  EXPECT_EQ(static_cast<int>(f.tracking), static_cast<int>(numbers(e, "tracking")[0]));
  if (e.count("weights")) expect_floats(numbers(e, "weights"), f.weights.data(), kBlendshapeCount, "weights");
  expect_pose(e, "head", f.has_head, f.head);
  expect_pose(e, "left_eye", f.has_eyes, f.left_eye);
  expect_pose(e, "right_eye", f.has_eyes, f.right_eye);
  if (e.count("landmarks")) {
    auto lm = numbers(e, "landmarks");
    ASSERT_EQ(f.landmark_count, static_cast<std::size_t>(lm[0]));
    lm.erase(lm.begin());
    expect_floats(lm, f.landmarks.data(), 3u * f.landmark_count, "landmarks");
    if (f.landmark_count) {
      EXPECT_EQ(f.profile_id, static_cast<uint32_t>(numbers(e, "profile_id")[0]));
    }
  }
}

}  // namespace

TEST(Golden, ThereAreGoldenPackets) { EXPECT_GE(golden_packets().size(), 12u); }

TEST(Golden, CppDecodersReadEveryGoldenPacketAndEncodersReproduceThem) {
  for (const std::string& name : golden_packets()) {
    SCOPED_TRACE(name);
    const auto bytes = test::read_bytes(test::golden_dir() + name + ".bin");
    const Section e = test::read_expected(test::golden_dir() + name + ".txt")[""];
    const std::string format = e.at("format"), kind = e.at("kind");
    const bool reencode = e.count("reencode") && e.at("reencode") == "1";
    std::vector<uint8_t> again;
    if (format == "softdeca") {
      wire::Message m;
      const auto verdict = wire::decode(bytes.data(), bytes.size(), m);
      if (kind == "drop") {
        const std::string reason = e.at("drop_reason");
        const DropReason want = reason == "unknown_type" ? DropReason::unknown_type : DropReason::incompatible_version;
        ASSERT_TRUE(reason == "unknown_type" || reason == "incompatible_version");
        EXPECT_EQ(verdict.reason, want);
        continue;
      }
      ASSERT_EQ(verdict.reason, DropReason::none) << verdict.detail;
      EXPECT_EQ(m.envelope.session_id, static_cast<uint32_t>(numbers(e, "session_id")[0]));
      EXPECT_EQ(m.envelope.sequence, static_cast<uint32_t>(numbers(e, "sequence")[0]));
      if (kind == "frame") {
        EXPECT_EQ(m.envelope.minor, numbers(e, "minor")[0]);
        expect_frame(e, m.frame);
        wire::encode_frame(m.frame, again);
      } else if (kind == "profile") {
        EXPECT_EQ(m.profile.id, static_cast<uint32_t>(numbers(e, "profile_id")[0]));
        EXPECT_EQ(m.profile.name, e.at("profile_name"));
        const auto idx = numbers(e, "indices");
        EXPECT_EQ(m.profile.indices, std::vector<uint16_t>(idx.begin(), idx.end()));
        wire::encode_profile(m.envelope.session_id, m.envelope.sequence, m.profile, again);
      } else if (kind == "neutral_chunk") {
        EXPECT_EQ(m.neutral.neutral_id, static_cast<uint32_t>(numbers(e, "neutral_id")[0]));
        EXPECT_EQ(m.neutral.total_vertices, numbers(e, "total_vertices")[0]);
        EXPECT_EQ(m.neutral.first_vertex, numbers(e, "first_vertex")[0]);
        auto xyz = numbers(e, "xyz");
        xyz.erase(xyz.begin());
        expect_floats(xyz, m.neutral.xyz.data(), m.neutral.xyz.size(), "xyz");
        wire::encode_neutral_chunk(m.envelope.session_id, m.envelope.sequence, m.neutral, again);
      } else {
        ASSERT_EQ(kind, "request");
        EXPECT_EQ(static_cast<int>(m.request.what), numbers(e, "request_what")[0]);
        EXPECT_EQ(m.request.id, static_cast<uint32_t>(numbers(e, "request_id")[0]));
        wire::encode_request(m.envelope.session_id, m.envelope.sequence, m.request, again);
      }
    } else if (format == "livelinkface") {
      Frame f;
      livelinkface::PacketInfo info;
      ASSERT_EQ(livelinkface::decode_packet(bytes.data(), bytes.size(), f, info).reason, DropReason::none);
      EXPECT_EQ(f.session_id, static_cast<uint32_t>(numbers(e, "session_id")[0]));
      EXPECT_EQ(info.frame_number, numbers(e, "frame_number")[0]);
      EXPECT_EQ(info.subframe, static_cast<float>(numbers(e, "subframe")[0]));
      if (e.count("device_id")) {
        EXPECT_EQ(info.device_id, e.at("device_id"));
      }
      expect_frame(e, f);
      if (e.count("values")) {
        const auto values = livelinkface::frame_to_values(f);
        auto want = numbers(e, "values");
        want.resize(52);  // the weights; angles pass through quaternions
        expect_floats(want, values.data(), 52, "values");
      }
      livelinkface::encode_packet(f, info, again);
    } else {
      ASSERT_EQ(format, "ifacialmocap");
      Frame f;
      ifacialmocap::Presence present;
      ASSERT_EQ(ifacialmocap::decode_packet(bytes.data(), bytes.size(), f, present).reason, DropReason::none);
      expect_frame(e, f);
      const auto want = numbers(e, "present");
      for (std::size_t i = 0; i < kBlendshapeCount; ++i) EXPECT_EQ(present[i], want[i] == 1) << i;
    }
    if (reencode) {
      EXPECT_EQ(again, bytes);
    }
  }
}

TEST(Golden, CppReaderReadsTheGoldenRecording) {
  const auto bytes = test::read_bytes(test::golden_dir() + "small.sdrec");
  const auto sections = test::read_expected(test::golden_dir() + "small.txt");
  const recording::Recording rec = recording::parse_recording(bytes.data(), bytes.size());
  const Section& h = sections.at("header");
  EXPECT_EQ(rec.header.device, h.at("device"));
  EXPECT_EQ(rec.header.subject, h.at("subject"));
  EXPECT_EQ(rec.header.source, h.at("source"));
  EXPECT_EQ(rec.header.clock, h.at("clock"));
  EXPECT_EQ(rec.header.units, h.at("units"));
  EXPECT_EQ(rec.header.start_unix_time, numbers(h, "start_unix_time")[0]);
  EXPECT_EQ(rec.header.timecode_rate, numbers(h, "timecode_rate")[0]);
  ASSERT_EQ(rec.frames.size(), numbers(h, "frames")[0]);
  ASSERT_EQ(rec.profiles.size(), numbers(h, "profiles")[0]);
  auto neutral = numbers(h, "neutral");
  neutral.erase(neutral.begin());
  expect_floats(neutral, rec.neutral.data(), rec.neutral.size(), "neutral");
  for (std::size_t i = 0; i < rec.profiles.size(); ++i) {
    const Section& s = sections.at("profile " + std::to_string(i));
    EXPECT_EQ(rec.profiles[i].id, static_cast<uint32_t>(numbers(s, "profile_id")[0]));
    EXPECT_EQ(rec.profiles[i].name, s.at("profile_name"));
  }
  for (std::size_t i = 0; i < rec.frames.size(); ++i) {
    SCOPED_TRACE(i);
    const Section& s = sections.at("frame " + std::to_string(i));
    EXPECT_EQ(rec.frames[i].session_id, numbers(s, "session_id")[0]);
    EXPECT_EQ(rec.frames[i].sequence, numbers(s, "sequence")[0]);
    EXPECT_EQ(rec.frames[i].receive_time, numbers(s, "receive_time")[0]);
    expect_frame(s, rec.frames[i]);
  }
  EXPECT_EQ(rec.recovery.records, 5u);
  EXPECT_EQ(rec.recovery.damaged_regions + rec.recovery.truncated_bytes + rec.recovery.skipped_bytes, 0u);
}
