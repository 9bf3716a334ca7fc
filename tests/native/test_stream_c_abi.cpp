// The streaming part of the C ABI: handles, size fields, hostile arguments, and one loopback
// stream received, recorded and played back through it.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "softdeca/softdeca.h"
#include "stream/frame_sender.h"
#include "stream_test_support.h"

namespace {

using softdeca::test::temp_path;

softdeca_frame blank_frame() {
  softdeca_frame f;
  std::memset(&f, 0, sizeof f);
  f.struct_size = sizeof f;
  f.tracking = SOFTDECA_TRACKING_TRACKED;
  f.head.rotation[3] = f.left_eye.rotation[3] = f.right_eye.rotation[3] = 1;
  return f;
}

softdeca_recording_header header() {
  softdeca_recording_header h{};
  h.struct_size = sizeof h;
  h.device = "abi test";
  return h;
}

}  // namespace

TEST(StreamCAbi, BlendshapeNames) {
  EXPECT_STREQ(softdeca_blendshape_get_name(0), "browDownLeft");
  EXPECT_STREQ(softdeca_blendshape_get_name(51), "tongueOut");
  EXPECT_EQ(softdeca_blendshape_get_name(52), nullptr);
}

TEST(StreamCAbi, RejectsNullsSmallStructsAndBadConfigs) {
  softdeca_receiver_config c{};
  EXPECT_EQ(softdeca_receiver_config_init(&c), SOFTDECA_ERROR_INVALID_ARGUMENT);  // size 0
  c.struct_size = sizeof c;
  ASSERT_EQ(softdeca_receiver_config_init(&c), SOFTDECA_OK);
  EXPECT_EQ(c.port, 50110u);
  softdeca_receiver* r = nullptr;
  EXPECT_EQ(softdeca_receiver_create(nullptr, &r), SOFTDECA_ERROR_INVALID_ARGUMENT);
  c.format = 9;
  EXPECT_EQ(softdeca_receiver_create(&c, &r), SOFTDECA_ERROR_INVALID_ARGUMENT);
  c.format = SOFTDECA_FORMAT_AUTO;
  c.port = 70000;
  EXPECT_EQ(softdeca_receiver_create(&c, &r), SOFTDECA_ERROR_INVALID_ARGUMENT);
  c.port = 0;
  c.jitter_delay = NAN;
  EXPECT_EQ(softdeca_receiver_create(&c, &r), SOFTDECA_ERROR_NON_FINITE);
  c.jitter_delay = 0;
  c.bind_address = "256.1.1.1";
  EXPECT_EQ(softdeca_receiver_create(&c, &r), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(softdeca_last_error()).find("256.1.1.1"), std::string::npos);
  EXPECT_EQ(r, nullptr);
  softdeca_frame f = blank_frame();
  softdeca_bool got = 7;
  EXPECT_EQ(softdeca_receiver_get_next(nullptr, 0, &f, &got), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(got, 7);
  softdeca_receiver_destroy(nullptr);
  softdeca_player* p = nullptr;
  EXPECT_EQ(softdeca_player_load(temp_path("none.sdrec").c_str(), &p), SOFTDECA_ERROR_IO);
  EXPECT_EQ(softdeca_player_load(nullptr, &p), SOFTDECA_ERROR_INVALID_ARGUMENT);
  softdeca_player_destroy(nullptr);
  softdeca_recorder_destroy(nullptr);
}

TEST(StreamCAbi, RecorderRejectsBadFramesAndPlayerPlaysWhatWasWritten) {
  const std::string path = temp_path("rec.sdrec");
  softdeca_recording_header h = header();
  softdeca_recorder* rec = nullptr;
  ASSERT_EQ(softdeca_recorder_create(path.c_str(), &h, &rec), SOFTDECA_OK);
  const int32_t indices[3] = {7, 8, 9};
  uint32_t id = 0;
  ASSERT_EQ(softdeca_recorder_write_profile(rec, "three", indices, 3, &id), SOFTDECA_OK);
  const int32_t repeated[2] = {7, 7};
  EXPECT_EQ(softdeca_recorder_write_profile(rec, "bad", repeated, 2, &id), SOFTDECA_ERROR_INVALID_ARGUMENT);
  const float neutral[6] = {0, 0.1f, 0.2f, 0.3f, 0.4f, 0.5f};
  ASSERT_EQ(softdeca_recorder_write_neutral(rec, neutral, 2), SOFTDECA_OK);
  for (int i = 0; i < 5; ++i) {
    softdeca_frame f = blank_frame();
    f.capture_time = 10 + 0.1 * i;
    f.weights[24] = 0.2f * float(i);
    f.flags = SOFTDECA_FRAME_HAS_HEAD;
    f.head.position[2] = -0.5f;
    f.profile_id = 0;
    f.landmark_count = 3;
    for (int k = 0; k < 9; ++k) f.landmarks[k] = 0.01f * float(k + i);
    ASSERT_EQ(softdeca_recorder_write(rec, &f), SOFTDECA_OK) << softdeca_last_error();
  }
  softdeca_frame bad = blank_frame();
  bad.weights[3] = 1.5f;
  EXPECT_EQ(softdeca_recorder_write(rec, &bad), SOFTDECA_ERROR_INVALID_ARGUMENT);
  bad = blank_frame();
  bad.landmark_count = 1;
  bad.landmarks[1] = INFINITY;
  EXPECT_EQ(softdeca_recorder_write(rec, &bad), SOFTDECA_ERROR_NON_FINITE);
  bad = blank_frame();
  bad.flags = SOFTDECA_FRAME_HAS_HEAD;
  bad.head.rotation[3] = 0;
  EXPECT_EQ(softdeca_recorder_write(rec, &bad), SOFTDECA_ERROR_INVALID_ARGUMENT);
  bad = blank_frame();
  bad.struct_size = 16;
  EXPECT_EQ(softdeca_recorder_write(rec, &bad), SOFTDECA_ERROR_INVALID_ARGUMENT);
  softdeca_recorder_destroy(rec);

  softdeca_player* p = nullptr;
  ASSERT_EQ(softdeca_player_load(path.c_str(), &p), SOFTDECA_OK);
  softdeca_recording_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(softdeca_player_get_info(p, &info), SOFTDECA_OK);
  EXPECT_EQ(info.frame_count, 5u);
  EXPECT_NEAR(info.duration, 0.4, 1e-12);
  EXPECT_STREQ(info.device, "abi test");
  int32_t out_idx[2];
  uint32_t count = 0;
  EXPECT_EQ(softdeca_player_get_profile(p, &id, out_idx, 2, &count), SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  EXPECT_EQ(count, 3u);
  int32_t all_idx[3];
  ASSERT_EQ(softdeca_player_get_profile(p, &id, all_idx, 3, &count), SOFTDECA_OK);
  EXPECT_EQ(all_idx[2], 9);
  float n[6];
  uint32_t vertices = 0;
  ASSERT_EQ(softdeca_player_get_neutral(p, n, 2, &vertices), SOFTDECA_OK);
  EXPECT_EQ(vertices, 2u);
  EXPECT_EQ(n[5], 0.5f);

  softdeca_frame f = blank_frame();
  ASSERT_EQ(softdeca_player_get_frame_at(p, 0.25, &f), SOFTDECA_OK);
  EXPECT_NEAR(f.weights[24], 0.5f, 1e-6);
  EXPECT_NEAR(f.capture_time, 10.25, 1e-9);
  EXPECT_EQ(f.landmark_count, 3u);
  EXPECT_EQ(softdeca_player_get_frame(p, 5, &f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(softdeca_player_set_loop(p, SOFTDECA_TRUE), SOFTDECA_OK);
  ASSERT_EQ(softdeca_player_set_speed(p, 2), SOFTDECA_OK);
  EXPECT_EQ(softdeca_player_set_speed(p, -1), SOFTDECA_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(softdeca_player_seek(p, 0.3), SOFTDECA_OK);
  softdeca_bool ended = 9;
  ASSERT_EQ(softdeca_player_advance(p, 0.1, &f, &ended), SOFTDECA_OK);  // 0.3 + 0.2 wraps to 0.1
  EXPECT_EQ(ended, 0);
  double pos = 0;
  ASSERT_EQ(softdeca_player_get_position(p, &pos), SOFTDECA_OK);
  EXPECT_NEAR(pos, 0.1, 1e-9);
  EXPECT_NEAR(f.weights[24], 0.2f, 1e-6);
  EXPECT_EQ(softdeca_player_get_frame_at(p, NAN, &f), SOFTDECA_ERROR_NON_FINITE);
  softdeca_player_destroy(p);
  std::remove(path.c_str());
}

TEST(StreamCAbi, ReceivesRecordsAndReportsOverLoopback) {
  softdeca_receiver_config c{};
  c.struct_size = sizeof c;
  softdeca_receiver_config_init(&c);
  c.bind_address = "127.0.0.1";
  c.port = 0;
  c.format = SOFTDECA_FORMAT_SOFTDECA;
  softdeca_receiver* r = nullptr;
  ASSERT_EQ(softdeca_receiver_create(&c, &r), SOFTDECA_OK) << softdeca_last_error();
  uint32_t port = 0;
  ASSERT_EQ(softdeca_receiver_get_port(r, &port), SOFTDECA_OK);
  ASSERT_GT(port, 0u);
  const std::string path = temp_path("received.sdrec");
  softdeca_recording_header h = header();
  ASSERT_EQ(softdeca_receiver_start_recording(r, path.c_str(), &h), SOFTDECA_OK);
  softdeca::stream::FrameSender s(softdeca::stream::make_endpoint("127.0.0.1", static_cast<uint16_t>(port)),
                                  softdeca::stream::Format::softdeca, 3);
  for (uint32_t i = 0; i < 10; ++i) ASSERT_TRUE(s.send(softdeca::test::make_frame(i)));
  softdeca_frame f = blank_frame();
  softdeca_bool got = 0;
  for (int i = 0; i < 10; ++i) {
    ASSERT_EQ(softdeca_receiver_get_next(r, 10.0, &f, &got), SOFTDECA_OK);
    ASSERT_EQ(got, 1);
    EXPECT_EQ(f.sequence, static_cast<uint32_t>(i));
    EXPECT_EQ(f.flags & SOFTDECA_FRAME_HAS_SEQUENCE, SOFTDECA_FRAME_HAS_SEQUENCE);
  }
  ASSERT_EQ(softdeca_receiver_get_latest(r, &f, &got), SOFTDECA_OK);
  EXPECT_EQ(f.sequence, 9u);
  ASSERT_EQ(softdeca_receiver_get_next(r, 0, &f, &got), SOFTDECA_OK);
  EXPECT_EQ(got, 0);
  softdeca_receiver_stats st{};
  st.struct_size = sizeof st;
  ASSERT_EQ(softdeca_receiver_get_stats(r, &st), SOFTDECA_OK);
  EXPECT_EQ(st.delivered, 10u);
  EXPECT_EQ(st.lost, 0u);
  uint32_t recorded = 0;
  ASSERT_EQ(softdeca_receiver_stop_recording(r, &recorded), SOFTDECA_OK);
  EXPECT_EQ(recorded, 10u);
  uint32_t id = 1;
  uint32_t count = 9;
  ASSERT_EQ(softdeca_receiver_get_profile(r, &id, nullptr, 0, &count), SOFTDECA_OK);
  EXPECT_EQ(count, 0u);
  EXPECT_EQ(id, 0u);
  softdeca_bool sent = 0;
  ASSERT_EQ(softdeca_receiver_request_neutral(r, &sent), SOFTDECA_OK);
  EXPECT_EQ(sent, 1);
  softdeca_receiver_destroy(r);

  softdeca_player* p = nullptr;
  ASSERT_EQ(softdeca_player_load(path.c_str(), &p), SOFTDECA_OK);
  softdeca_recording_info info{};
  info.struct_size = sizeof info;
  softdeca_player_get_info(p, &info);
  EXPECT_EQ(info.frame_count, 10u);
  softdeca_player_destroy(p);
  std::remove(path.c_str());
}

TEST(StreamCAbi, ConvertsLiveLinkFaceCsv) {
  const std::string rec = temp_path("apfel.sdrec"), csv = temp_path("apfel.csv");
  softdeca_convert_report report{};
  report.struct_size = sizeof report;
  ASSERT_EQ(softdeca_convert_livelinkface_csv((softdeca::test::takes_dir() + "apfel.csv").c_str(), rec.c_str(), 0,
                                              &report),
            SOFTDECA_OK)
      << softdeca_last_error();
  EXPECT_EQ(report.rows, 1926u);
  EXPECT_EQ(report.face_lost_rows, 35u);
  EXPECT_EQ(report.frames, 1891u);
  ASSERT_EQ(softdeca_export_livelinkface_csv(rec.c_str(), csv.c_str(), 0, &report), SOFTDECA_OK);
  EXPECT_EQ(report.frames, 1891u);
  EXPECT_EQ(softdeca_export_livelinkface_csv(rec.c_str(), csv.c_str(), 29.97, nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_convert_livelinkface_csv(rec.c_str(), csv.c_str(), 0, nullptr), SOFTDECA_ERROR_FORMAT);
  std::remove(rec.c_str());
  std::remove(csv.c_str());
}
