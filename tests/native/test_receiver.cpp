// The receiver on loopback (127.0.0.1 only): frames come out in order and equal to what was
// sent (within the quantisation), under loss, reordering and duplication with exact
// statistics; hostile datagrams are dropped and counted; the three formats; profile and neutral
// requests; recording what is received. Waits are bounded; nothing asserts a duration.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <functional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "live/receiver.h"
#include "recording/recording_reader.h"
#include "stream/frame_sender.h"
#include "stream/ifacialmocap_packet.h"
#include "stream/livelinkface_packet.h"
#include "stream/wire_format.h"
#include "receiver_test_support.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::live;
using namespace softdeca::stream;
using test::eventually;
using test::loopback;
using test::make_frame;

namespace {

std::vector<Frame> take_all(Receiver& r) {
  std::vector<Frame> out;
  Frame f;
  while (r.next(0, f)) out.push_back(f);
  return out;
}

wire::Profile sample_profile() {
  wire::Profile p;
  p.name = "loopback";
  p.indices = {10, 20, 30, 40, 50, 60, 70, 80};
  p.id = wire::profile_id_of(p.indices);
  return p;
}

}  // namespace

TEST(Receiver, ExactStatisticsUnderLossReorderingAndDuplication) {
  Receiver r(loopback(Format::softdeca, 0.3));
  FrameSender s(make_endpoint("127.0.0.1", r.port()), Format::softdeca, 42);
  const std::set<uint32_t> dropped = {20, 50, 51, 120};
  const std::set<uint32_t> doubled = {30, 90};
  const std::set<uint32_t> swapped = {60, 150};  // sent after their successor
  std::vector<std::vector<uint8_t>> datagrams(200);
  for (uint32_t i = 0; i < 200; ++i) {
    Frame f = make_frame(i, 8, sample_profile().id);
    f.session_id = 42;
    f.sequence = i;
    f.send_time = f.capture_time;
    wire::encode_frame(f, datagrams[i]);
  }
  std::size_t sent = 0;
  for (uint32_t i = 0; i < 200; ++i) {
    const uint32_t k = swapped.count(i) ? i + 1 : (i > 0 && swapped.count(i - 1) ? i - 1 : i);
    if (dropped.count(k)) continue;
    for (int copy = 0; copy < (doubled.count(k) ? 2 : 1); ++copy, ++sent)
      ASSERT_TRUE(s.send_raw(datagrams[k].data(), datagrams[k].size()));
  }
  ASSERT_EQ(sent, 198u);
  ASSERT_TRUE(eventually([&] { return r.stats().datagrams == sent; })) << r.stats().datagrams;
  r.stop();
  const ReceiverStats st = r.stats();
  EXPECT_EQ(st.frames, 196u);
  EXPECT_EQ(st.duplicates, 2u);
  EXPECT_EQ(st.reordered, 2u);
  EXPECT_EQ(st.lost, 4u);
  EXPECT_EQ(st.expected, 200u);
  EXPECT_EQ(st.late, 0u);
  EXPECT_EQ(st.malformed, 0u);
  EXPECT_EQ(st.delivered, 196u);
  EXPECT_DOUBLE_EQ(st.loss_ratio, 4.0 / 200.0);
  EXPECT_GE(st.requests_sent, 1u);  // the frames' landmark profile was unknown
  const auto frames = take_all(r);
  ASSERT_EQ(frames.size(), 196u);
  uint32_t expect = 0;
  for (const Frame& f : frames) {
    while (dropped.count(expect)) ++expect;
    const Frame want = make_frame(expect, 8, sample_profile().id);
    ASSERT_EQ(f.sequence, expect);
    EXPECT_EQ(f.capture_time, want.capture_time);
    for (std::size_t k = 0; k < kBlendshapeCount; ++k) EXPECT_NEAR(f.weights[k], want.weights[k], 0.5 / 65535 + 1e-7);
    for (std::size_t k = 0; k < 24; ++k) EXPECT_NEAR(f.landmarks[k], want.landmarks[k], 5e-6 + 1e-9);
    EXPECT_GT(f.receive_time, 0.0);
    ++expect;
  }
}

TEST(Receiver, ADelayOfZeroDeliversAtOnceAndDropsWhatComesLate) {
  Receiver r(loopback(Format::softdeca, 0.0));
  FrameSender s(make_endpoint("127.0.0.1", r.port()), Format::softdeca, 7);
  std::vector<uint8_t> a, b;
  Frame f0 = make_frame(0), f1 = make_frame(1);
  f0.session_id = f1.session_id = 7;
  f0.sequence = 0;
  f1.sequence = 1;
  wire::encode_frame(f0, a);
  wire::encode_frame(f1, b);
  s.send_raw(b.data(), b.size());
  Frame got;
  ASSERT_TRUE(r.next(10.0, got));
  EXPECT_EQ(got.sequence, 1u);
  s.send_raw(a.data(), a.size());  // older than a delivered frame
  ASSERT_TRUE(eventually([&] { return r.stats().datagrams == 2; }));
  ASSERT_TRUE(eventually([&] { return r.stats().late == 1; }));
  EXPECT_EQ(r.stats().reordered, 0u);  // frame 0 came before the first one seen: stale, not reordered
  EXPECT_FALSE(r.next(0, got));
}

TEST(Receiver, HostileDatagramsAreDroppedAndCountedAndTheStreamGoesOn) {
  Receiver r(loopback(Format::automatic, 0.0));
  FrameSender s(make_endpoint("127.0.0.1", r.port()), Format::softdeca, 99);
  std::vector<uint8_t> good;
  Frame f = make_frame(1);
  f.session_id = 99;
  wire::encode_frame(f, good);
  std::vector<std::vector<uint8_t>> bad;
  bad.push_back(std::vector<uint8_t>(good.begin(), good.begin() + 10));                      // undersized
  bad.push_back(good), bad.back().resize(3000);                                               // oversized
  bad.push_back({0xFF, 0xFE, 0x00, 0x01, 0x02});                                              // bad magic
  bad.push_back(good), bad.back()[4] = 9;                                                     // version 9.x
  bad.push_back(good), bad.back()[38] = 0xFF;                                                 // lying length
  bad.push_back(good), bad.back()[32] = 9;                                                    // bad value
  bad.push_back(good), bad.back()[6] = 77;                                                    // a newer type
  bad.push_back(std::vector<uint8_t>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(good.size() - 1)));
  for (const auto& d : bad) ASSERT_TRUE(s.send_raw(d.data(), d.size()));
  ASSERT_TRUE(s.send_raw(good.data(), good.size()));
  Frame got;
  ASSERT_TRUE(r.next(10.0, got));
  EXPECT_EQ(got.capture_time, f.capture_time);
  ASSERT_TRUE(eventually([&] { return r.stats().datagrams == bad.size() + 1; }));
  const ReceiverStats st = r.stats();
  EXPECT_EQ(st.undersized, 1u);
  EXPECT_EQ(st.oversized, 1u);
  EXPECT_EQ(st.bad_magic, 1u);
  EXPECT_EQ(st.incompatible_version, 1u);
  EXPECT_EQ(st.bad_length, 2u);
  EXPECT_EQ(st.bad_value, 1u);
  EXPECT_EQ(st.unknown_type, 1u);
  EXPECT_EQ(st.malformed, 7u);
  EXPECT_EQ(st.frames, 1u);
  EXPECT_EQ(st.delivered, 1u);
}

TEST(Receiver, AutomaticFormatTakesLiveLinkFaceAndIFacialMocapToo) {
  ReceiverConfig c = loopback(Format::automatic, 0.0);
  c.follow_newest = true;  // two senders, one after the other (docs/security.md)
  Receiver r(c);
  const Endpoint to = make_endpoint("127.0.0.1", r.port());
  FrameSender llf(to, Format::livelinkface, 0);
  Frame f = make_frame(4);
  f.capture_time = 3600.5;
  ASSERT_TRUE(llf.send(f));
  Frame got;
  ASSERT_TRUE(r.next(10.0, got));
  EXPECT_NEAR(got.capture_time, 3600.5, 1e-6);
  EXPECT_EQ(got.weights, f.weights);
  EXPECT_EQ(got.session_id, livelinkface::session_id_of("softdeca-sender", "take"));
  ASSERT_TRUE(llf.send(f));  // the same frame time again: a duplicate
  ASSERT_TRUE(eventually([&] { return r.stats().duplicates == 1; }));

  FrameSender ifm(to, Format::ifacialmocap, 0);
  const std::string first = "jawOpen-40|mouthSmile_L-10|", second = "mouthSmile_L-30|";
  ifm.send_raw(reinterpret_cast<const uint8_t*>(first.data()), first.size());
  ASSERT_TRUE(r.next(10.0, got));
  EXPECT_FLOAT_EQ(got.weights[static_cast<std::size_t>(blendshape_index("jawOpen"))], 0.4f);
  ifm.send_raw(reinterpret_cast<const uint8_t*>(second.data()), second.size());
  ASSERT_TRUE(r.next(10.0, got));
  EXPECT_FLOAT_EQ(got.weights[static_cast<std::size_t>(blendshape_index("jawOpen"))], 0.4f);  // kept, not zeroed
  EXPECT_FLOAT_EQ(got.weights[static_cast<std::size_t>(blendshape_index("mouthSmileLeft"))], 0.3f);
  EXPECT_GT(got.capture_time, 0.0);  // stamped on arrival: the format has no clock
  EXPECT_EQ(r.stats().session_changes, 1u);
}

TEST(Receiver, AsksForAnUnknownProfileAndForTheNeutralMesh) {
  Receiver r(loopback(Format::softdeca, 0.0));
  FrameSender s(make_endpoint("127.0.0.1", r.port()), Format::softdeca, 5);
  const wire::Profile p = sample_profile();
  std::vector<float> neutral(3 * kArkitVertexCount);
  for (std::size_t i = 0; i < neutral.size(); ++i) neutral[i] = 0.0001f * float(i % 997);
  ASSERT_TRUE(s.send(make_frame(0, 8, p.id)));
  ASSERT_TRUE(eventually([&] { return r.stats().requests_sent == 1; }));
  ASSERT_TRUE(eventually([&] { return s.answer_requests(&p, &neutral) == 1; }));
  wire::Profile got;
  ASSERT_TRUE(eventually([&] { return r.profile(got); }));
  EXPECT_EQ(got.indices, p.indices);
  std::vector<float> n;
  EXPECT_FALSE(r.neutral(n));
  ASSERT_TRUE(r.request_neutral());
  ASSERT_TRUE(eventually([&] { return s.answer_requests(&p, &neutral) == 1; }));
  ASSERT_TRUE(eventually([&] { return r.neutral(n); }));
  EXPECT_EQ(n, neutral);
  EXPECT_EQ(r.stats().control_messages, 1u + 16u);
}

TEST(Receiver, RecordsWhatItDelivers) {
  const std::string path = test::temp_path("receiver.sdrec");
  Receiver r(loopback(Format::softdeca, 0.05));
  recording::Header h;
  h.device = "loopback";
  r.start_recording(path, h);
  FrameSender s(make_endpoint("127.0.0.1", r.port()), Format::softdeca, 11);
  const wire::Profile p = sample_profile();
  std::vector<float> neutral(3 * 10, 0.02f);
  ASSERT_TRUE(s.send_profile(p));
  ASSERT_TRUE(s.send_neutral(neutral));
  for (uint32_t i = 0; i < 30; ++i) ASSERT_TRUE(s.send(make_frame(i, 8, p.id)));
  ASSERT_TRUE(eventually([&] { return r.stats().datagrams == 32; }));
  r.stop();
  EXPECT_EQ(r.frames_recorded(), 30u);
  EXPECT_EQ(r.stop_recording(), "");
  const recording::Recording rec = recording::read_recording(path);
  EXPECT_EQ(rec.header.device, "loopback");
  ASSERT_EQ(rec.frames.size(), 30u);
  ASSERT_EQ(rec.profiles.size(), 1u);
  EXPECT_EQ(rec.profiles[0].indices, p.indices);
  EXPECT_EQ(rec.neutral, neutral);
  for (uint32_t i = 0; i < 30; ++i) {
    EXPECT_EQ(rec.frames[i].sequence, i + 2);  // after the profile and the neutral chunk
    EXPECT_EQ(rec.frames[i].capture_time, make_frame(i).capture_time);
    EXPECT_GT(rec.frames[i].send_time, 0.0);
  }
  std::remove(path.c_str());
}

TEST(Receiver, RefusesBadConfigurationsAndTakenPorts) {
  ReceiverConfig c = loopback(Format::softdeca, 0.3);
  c.delay = -1;
  EXPECT_THROW(Receiver{c}, Error);
  c = loopback(Format::softdeca, 0.3);
  c.bind_address = "not-an-address";
  EXPECT_THROW(Receiver{c}, Error);
  Receiver first(loopback(Format::softdeca, 0.3));
  c = loopback(Format::softdeca, 0.3);
  c.port = first.port();
  EXPECT_THROW(Receiver{c}, Error);
}
