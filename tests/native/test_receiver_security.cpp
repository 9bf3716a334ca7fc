// The receiver as something on a network (docs/security.md): loopback unless told, a held
// session, per-source rate limits, a flood from many ports, and a recording on a disk that
// cannot keep up.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "live/receiver.h"
#include "recording/recording_reader.h"
#include "stream/frame_sender.h"
#include "stream/source_rate_limit.h"
#include "receiver_test_support.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::live;
using namespace softdeca::stream;
using test::eventually;
using test::loopback;
using test::make_frame;

namespace {

std::size_t drain(Receiver& r) {
  std::size_t n = 0;
  Frame f;
  while (r.next(0, f)) ++n;
  return n;
}

}  // namespace

TEST(ReceiverSecurity, ListensOnLoopbackUnlessToldToListenOnTheNetwork) {
  EXPECT_EQ(ReceiverConfig().bind_address, "127.0.0.1");
  ReceiverConfig c = loopback();
  c.bind_address = "0.0.0.0";
  try {
    Receiver r(c);
    FAIL() << "bound all interfaces without listen_network";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("listen_network"), std::string::npos) << e.what();
  }
  c.listen_network = true;
  EXPECT_NO_THROW(Receiver{c});
  c = loopback();
  c.session_hold = 0;
  EXPECT_THROW(Receiver{c}, Error);
  c = loopback();
  c.source_rate_limit = -1;
  EXPECT_THROW(Receiver{c}, Error);
}

TEST(ReceiverSecurity, SecondSenderCannotTakeOverAHeldSession) {
  ReceiverConfig c = loopback();
  c.session_hold = 0.5;
  Receiver r(c);
  const Endpoint to = make_endpoint("127.0.0.1", r.port());
  FrameSender owner(to, Format::softdeca, 1), intruder(to, Format::softdeca, 2);
  for (uint32_t i = 0; i < 5; ++i) ASSERT_TRUE(owner.send(make_frame(i)));
  ASSERT_TRUE(eventually([&] { return r.stats().delivered == 5; }));
  // The intruder sends while the owner keeps sending: none of its frames gets through.
  for (uint32_t i = 0; i < 20; ++i) {
    ASSERT_TRUE(intruder.send(make_frame(100 + i)));
    if (i % 4 == 0) {
      ASSERT_TRUE(owner.send(make_frame(5 + i / 4)));
    }
  }
  ASSERT_TRUE(eventually([&] { return r.stats().foreign == 20; }));
  EXPECT_EQ(r.stats().session_changes, 0u);
  Frame f;
  while (r.next(0, f)) {
    EXPECT_EQ(f.session_id, 1u);
  }
  // Once the owner has been quiet for the hold time, a new sender may take the session.
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  ASSERT_TRUE(intruder.send(make_frame(200)));
  ASSERT_TRUE(r.next(10.0, f));
  EXPECT_EQ(f.session_id, 2u);
  EXPECT_EQ(r.stats().session_changes, 1u);
}

TEST(ReceiverSecurity, FollowNewestLetsANewSenderTakeOverAtOnce) {
  ReceiverConfig c = loopback();
  c.follow_newest = true;
  Receiver r(c);
  const Endpoint to = make_endpoint("127.0.0.1", r.port());
  FrameSender first(to, Format::softdeca, 1), second(to, Format::softdeca, 2);
  ASSERT_TRUE(first.send(make_frame(0)));
  Frame f;
  ASSERT_TRUE(r.next(10.0, f));
  ASSERT_TRUE(second.send(make_frame(1)));
  ASSERT_TRUE(r.next(10.0, f));
  EXPECT_EQ(f.session_id, 2u);
  EXPECT_EQ(r.stats().foreign, 0u);
}

TEST(ReceiverSecurity, EachSourceIsRateLimited) {
  SourceRateLimit limit(40);  // burst of 10
  const Endpoint a = make_endpoint("127.0.0.1", 1000), b = make_endpoint("127.0.0.1", 1001);
  int passed = 0;
  for (int i = 0; i < 100; ++i) passed += limit.allow(a, 5.0);
  EXPECT_EQ(passed, 10);
  EXPECT_TRUE(limit.allow(b, 5.0));  // another source has its own bucket
  EXPECT_FALSE(limit.allow(a, 5.01));
  EXPECT_TRUE(limit.allow(a, 5.03));  // 40 per second: one more after 25 ms
  // The table of sources stays bounded under many ports.
  SourceRateLimit small(40, 16);
  for (uint16_t port = 2000; port < 2300; ++port) small.allow(make_endpoint("127.0.0.1", port), 1.0);
  EXPECT_EQ(small.sources(), 16u);
}

// Datagrams the rate limit drops are counted there, not again as lost: the holder's sequence
// numbers they leave out are no loss on the network.
TEST(ReceiverSecurity, RateLimitedDatagramsAreNotCountedAsLost) {
  ReceiverConfig c = loopback();
  c.source_rate_limit = 40;  // burst of 10
  Receiver r(c);
  FrameSender s(make_endpoint("127.0.0.1", r.port()), Format::softdeca, 9);
  for (uint32_t i = 0; i < 100; ++i) ASSERT_TRUE(s.send(make_frame(i)));
  ASSERT_TRUE(eventually([&] { return r.stats().datagrams == 100; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // a few tokens back
  ASSERT_TRUE(s.send(make_frame(100)));                         // after the gap the limit left
  ASSERT_TRUE(eventually([&] { return r.stats().datagrams == 101; }));
  const ReceiverStats st = r.stats();
  EXPECT_GE(st.rate_limited, 80u);
  EXPECT_EQ(st.lost, 0u);
  EXPECT_EQ(st.expected, 101u);
}

// The flood of the review: iFacialMocap datagrams from 200 source ports on loopback while
// recording. Bounded: 200 senders x 25 datagrams, sent as fast as the socket takes them.
TEST(ReceiverSecurity, FloodFromManyPortsKeepsTheSessionAndBoundsTheRecording) {
  ReceiverConfig c = loopback(Format::ifacialmocap);
  c.queue_capacity = 65536;
  Receiver r(c);
  const std::string path = test::temp_path("flood.sdrec");
  recording::Header h;
  h.source = "flood";
  r.start_recording(path, h);
  const Endpoint to = make_endpoint("127.0.0.1", r.port());
  std::vector<std::unique_ptr<FrameSender>> senders;
  for (int i = 0; i < 200; ++i) senders.push_back(std::make_unique<FrameSender>(to, Format::ifacialmocap, 0));
  const std::string text = "jawOpen-40|mouthSmile_L-10|eyeBlink_R-3|";
  const auto start = std::chrono::steady_clock::now();
  for (int round = 0; round < 25; ++round)
    for (auto& s : senders) s->send_raw(reinterpret_cast<const uint8_t*>(text.data()), text.size());
  ASSERT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  drain(r);
  r.stop();
  r.stop_recording();
  const ReceiverStats s = r.stats();
  EXPECT_LE(s.session_changes, 2u);
  EXPECT_GT(s.foreign, 0u);
  EXPECT_LE(r.frames_recorded(), s.delivered);
  // Accepted frames: one source, within its rate limit's burst and refill over the flood.
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LE(double(s.delivered), std::max(8.0, c.source_rate_limit / 4) + c.source_rate_limit * seconds + 1);
  const recording::Recording rec = recording::read_recording(path);
  EXPECT_EQ(rec.frames.size(), r.frames_recorded());
  std::remove(path.c_str());
}

// A recording whose "disk" is a pipe nobody reads: the writer thread blocks once the pipe is
// full, frames keep arriving on time and the recording drops (and counts) what it cannot take.
TEST(ReceiverSecurity, SlowDiskDropsRecordedFramesWithoutBlockingThePoll) {
  int ends[2];
  ASSERT_EQ(::pipe(ends), 0);
  const int reader = ends[0];
  ASSERT_EQ(::fcntl(reader, F_SETFL, O_NONBLOCK), 0);
  ReceiverConfig c = loopback();
  c.source_rate_limit = 0;
  c.recording_queue = 16;
  Receiver r(c);
  recording::Header h;
  r.start_recording(std::make_unique<recording::RecordingWriter>(FilePtr(::fdopen(ends[1], "wb")), "pipe", h), h);
  FrameSender s(make_endpoint("127.0.0.1", r.port()), Format::softdeca, 7);
  const int n = 2000;
  double worst_poll = 0;
  Frame f;
  for (int i = 0; i < n; ++i) {
    Frame frame = make_frame(static_cast<uint32_t>(i), 64, 5);
    ASSERT_TRUE(s.send(frame));
    const auto t0 = std::chrono::steady_clock::now();
    r.latest(f);
    r.next(0, f);
    worst_poll = std::max(worst_poll, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  ASSERT_TRUE(eventually([&] { return r.stats().delivered == static_cast<uint64_t>(n); }));
  const ReceiverStats st = r.stats();
  EXPECT_GT(st.recording_dropped, 0u);  // the pipe holds 64 KiB; 2000 frames are far more
  EXPECT_LT(worst_poll, 1.0) << "a poll waited for the disk";
  // Drain the pipe so that the writer thread can finish.
  std::atomic<bool> done{false};
  std::thread drainer([&] {
    char buf[65536];
    while (!done.load()) {
      if (::read(reader, buf, sizeof buf) <= 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  r.stop_recording();
  done = true;
  drainer.join();
  ::close(reader);
  EXPECT_EQ(r.frames_recorded() + st.recording_dropped, static_cast<std::size_t>(n));
}
