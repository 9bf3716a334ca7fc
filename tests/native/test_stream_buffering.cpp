// Sequence tracking, the jitter buffer and neutral-mesh assembly, on explicit times: exact
// behaviour without a network or a clock.
#include <gtest/gtest.h>

#include <vector>

#include "stream/jitter_buffer.h"
#include "stream/neutral_assembler.h"
#include "stream/sequence_tracker.h"
#include "stream_test_support.h"

using namespace softdeca::stream;

TEST(SequenceTracker, CountsLossReorderingAndDuplicates) {
  SequenceTracker t;
  EXPECT_EQ(t.observe(10), Arrival::in_order);
  EXPECT_EQ(t.observe(11), Arrival::in_order);
  EXPECT_EQ(t.observe(14), Arrival::in_order);  // 12 and 13 missing
  EXPECT_EQ(t.lost(), 2u);
  EXPECT_EQ(t.observe(12), Arrival::reordered);
  EXPECT_EQ(t.lost(), 1u);
  EXPECT_EQ(t.observe(12), Arrival::duplicate);
  EXPECT_EQ(t.observe(14), Arrival::duplicate);
  EXPECT_EQ(t.observe(9), Arrival::stale);  // before the first one seen
  EXPECT_EQ(t.expected(), 5u);              // 10..14
  EXPECT_EQ(t.lost(), 1u);
}

TEST(SequenceTracker, WrapsAroundTheCounter) {
  SequenceTracker t;
  t.observe(0xFFFFFFFEu);
  EXPECT_EQ(t.observe(0xFFFFFFFFu), Arrival::in_order);
  EXPECT_EQ(t.observe(1), Arrival::in_order);  // 0 skipped
  EXPECT_EQ(t.lost(), 1u);
  EXPECT_EQ(t.observe(0), Arrival::reordered);
  EXPECT_EQ(t.lost(), 0u);
}

TEST(SequenceTracker, OldNumbersBeyondTheWindowAreStaleAndJumpsRestart) {
  SequenceTracker t;
  t.observe(0);
  t.observe(5000);
  EXPECT_EQ(t.lost(), 4999u);
  EXPECT_EQ(t.observe(100), Arrival::stale);  // 4900 behind: outside the 1024 window
  EXPECT_EQ(t.observe(5000 + (1u << 20)), Arrival::restart);
  EXPECT_EQ(t.lost(), 4999u);  // a restart is no loss
  EXPECT_EQ(t.observe(5001 + (1u << 20)), Arrival::in_order);
}

namespace {
Frame at(double capture) {
  Frame f;
  f.capture_time = capture;
  return f;
}
std::vector<double> drain(JitterBuffer& b, double now) {
  std::vector<double> out;
  Frame f;
  while (b.pop_due(now, f)) out.push_back(f.capture_time);
  return out;
}
}  // namespace

TEST(JitterBuffer, ReleasesInCaptureOrderAfterTheDelay) {
  JitterBuffer b(0.1);
  // Sender clock 0-based, ours 1000-based; the fastest path took 5 ms.
  EXPECT_EQ(b.insert(at(0.000), 1000.005), JitterBuffer::Outcome::queued);
  EXPECT_EQ(b.insert(at(0.033), 1000.040), JitterBuffer::Outcome::queued);  // 7 ms
  EXPECT_EQ(b.insert(at(0.100), 1000.106), JitterBuffer::Outcome::queued);
  EXPECT_EQ(b.insert(at(0.067), 1000.110), JitterBuffer::Outcome::queued);  // reordered, 43 ms late
  EXPECT_TRUE(drain(b, 1000.100).empty());
  EXPECT_NEAR(b.next_due(), 1000.105, 1e-9);  // capture 0 + offset 5 ms + delay 100 ms
  EXPECT_EQ(drain(b, 1000.180), (std::vector<double>{0.000, 0.033, 0.067}));
  EXPECT_EQ(drain(b, 1000.300), (std::vector<double>{0.100}));
}

TEST(JitterBuffer, LateAndDuplicateFramesAreRefused) {
  JitterBuffer b(0.0);
  b.insert(at(1.0), 10.0);
  b.insert(at(2.0), 11.0);
  EXPECT_EQ(drain(b, 11.0).size(), 2u);
  EXPECT_EQ(b.insert(at(1.5), 11.2), JitterBuffer::Outcome::late);
  EXPECT_EQ(b.insert(at(2.0), 11.2), JitterBuffer::Outcome::duplicate);
  JitterBuffer d(1.0);
  d.insert(at(1.0), 10.0);
  EXPECT_EQ(d.insert(at(1.0), 10.1), JitterBuffer::Outcome::duplicate);
}

TEST(JitterBuffer, AClockJumpFlushesAndStartsAfresh) {
  JitterBuffer b(0.5);
  b.insert(at(86399.9), 50.0);  // a timecode just before midnight
  EXPECT_EQ(b.insert(at(0.05), 50.1), JitterBuffer::Outcome::resync);
  EXPECT_EQ(drain(b, 50.1), (std::vector<double>{86399.9}));  // out at once
  EXPECT_EQ(drain(b, 50.7), (std::vector<double>{0.05}));
  EXPECT_EQ(b.insert(at(0.08), 50.8), JitterBuffer::Outcome::queued);
}

TEST(JitterBuffer, StaysBoundedWhenNothingFallsDue) {
  JitterBuffer b(5.0);
  for (int i = 0; i < int(JitterBuffer::kCapacity) + 10; ++i) b.insert(at(i * 0.001), 0.0);
  EXPECT_EQ(drain(b, 0.0).size(), 10u);
}

TEST(NeutralAssembler, AssemblesChunksInAnyOrderAndChecksTheId) {
  std::vector<float> xyz(3 * 200);
  for (std::size_t i = 0; i < xyz.size(); ++i) xyz[i] = 0.0001f * float(i);
  auto chunks = wire::split_neutral(xyz.data(), 200);
  ASSERT_EQ(chunks.size(), 3u);
  NeutralAssembler a;
  std::vector<float> out;
  EXPECT_FALSE(a.add(chunks[2], out));
  EXPECT_FALSE(a.add(chunks[0], out));
  EXPECT_FALSE(a.add(chunks[0], out));
  EXPECT_TRUE(a.add(chunks[1], out));
  EXPECT_EQ(out, xyz);
  // A chunk whose data does not match the mesh's id is caught when the mesh completes.
  chunks[1].xyz[0] += 1.0f;
  std::vector<float> bad;
  a.add(chunks[0], bad);
  a.add(chunks[1], bad);
  EXPECT_FALSE(a.add(chunks[2], bad));
  EXPECT_TRUE(bad.empty());
}
