// Our wire format: round trips within the stated quantisation, sizes, versioning, and hostile
// datagrams dropped with the right reason and never read out of bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/error.h"
#include "stream/byte_io.h"
#include "stream/wire_format.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::stream;
using test::make_frame;

namespace {
wire::Profile profile_of(std::vector<uint16_t> indices, std::string name = "p") {
  wire::Profile p;
  p.name = std::move(name);
  p.indices = std::move(indices);
  p.id = wire::profile_id_of(p.indices);
  return p;
}

DropReason decode_reason(const std::vector<uint8_t>& bytes) {
  wire::Message m;
  return wire::decode(bytes.data(), bytes.size(), m).reason;
}
}  // namespace

TEST(WireFormat, FrameRoundTripsWithinTheQuantisation) {
  Frame f = make_frame(3, kMaxLandmarks, 0xABCD1234);
  f.session_id = 77;
  f.sequence = 123456;
  f.send_time = 101.5;
  f.tracking = Tracking::limited;
  std::vector<uint8_t> bytes;
  wire::encode_frame(f, bytes);
  EXPECT_LT(bytes.size(), wire::kDatagramLimit);
  wire::Message m;
  ASSERT_EQ(wire::decode(bytes.data(), bytes.size(), m).reason, DropReason::none);
  const Frame& g = m.frame;
  EXPECT_EQ(m.envelope.type, wire::MessageType::frame);
  EXPECT_EQ(g.session_id, 77u);
  EXPECT_EQ(g.sequence, 123456u);
  EXPECT_TRUE(g.has_sequence);
  EXPECT_EQ(g.capture_time, f.capture_time);
  EXPECT_EQ(g.send_time, 101.5);
  EXPECT_EQ(g.tracking, Tracking::limited);
  for (std::size_t i = 0; i < kBlendshapeCount; ++i) EXPECT_NEAR(g.weights[i], f.weights[i], 0.5 / 65535 + 1e-7);
  ASSERT_TRUE(g.has_head && g.has_eyes);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(g.head.rotation[k], f.head.rotation[k], 1e-7);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(g.head.position[k], f.head.position[k]);
  EXPECT_EQ(g.profile_id, 0xABCD1234u);
  ASSERT_EQ(g.landmark_count, kMaxLandmarks);
  for (std::size_t i = 0; i < 3 * kMaxLandmarks; ++i)
    EXPECT_NEAR(g.landmarks[i], f.landmarks[i], 0.5 * wire::kLandmarkStep + 1e-9);  // 5 micrometres
}

TEST(WireFormat, EveryMessageFitsUnder1200Bytes) {
  std::vector<uint8_t> bytes;
  wire::encode_frame(make_frame(0, kMaxLandmarks, 1), bytes);
  EXPECT_LT(bytes.size(), 1200u);
  EXPECT_EQ(bytes.size(), 1148u);  // 51 bytes to spare for blocks of later minor versions
  std::vector<uint16_t> indices(kMaxLandmarks);
  for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<uint16_t>(i * 8);
  wire::encode_profile(1, 2, profile_of(indices, std::string(64, 'n')), bytes);
  EXPECT_LT(bytes.size(), 1200u);
  std::vector<float> neutral(3 * kArkitVertexCount, 0.05f);
  const auto chunks = wire::split_neutral(neutral.data(), kArkitVertexCount);
  EXPECT_EQ(chunks.size(), 16u);
  for (const auto& c : chunks) {
    wire::encode_neutral_chunk(1, 2, c, bytes);
    EXPECT_LT(bytes.size(), 1200u);
  }
}

TEST(WireFormat, EncoderRefusesWhatTheFormatCannotCarry) {
  std::vector<uint8_t> bytes;
  Frame f = make_frame(0, 3, 1);
  f.landmarks[4] = 0.4f;  // beyond the +0.32767 m the format carries
  EXPECT_THROW(wire::encode_frame(f, bytes), Error);
  f = make_frame(0);
  f.weights[7] = std::nanf("");
  EXPECT_THROW(wire::encode_frame(f, bytes), Error);
  f = make_frame(0);
  f.landmark_count = kMaxLandmarks + 1;
  EXPECT_THROW(wire::encode_frame(f, bytes), Error);
  wire::Profile p = profile_of({1, 2, 3});
  p.id ^= 1;
  EXPECT_THROW(wire::encode_profile(0, 0, p, bytes), Error);
  EXPECT_THROW(wire::encode_profile(0, 0, profile_of({1, 1}), bytes), Error);
  EXPECT_THROW(wire::encode_profile(0, 0, profile_of({1220}), bytes), Error);
}

TEST(WireFormat, WeightsOutsideZeroOneAreClamped) {
  Frame f = make_frame(0);
  f.weights[0] = -0.5f;
  f.weights[1] = 1.5f;
  std::vector<uint8_t> bytes;
  wire::encode_frame(f, bytes);
  wire::Message m;
  ASSERT_EQ(wire::decode(bytes.data(), bytes.size(), m).reason, DropReason::none);
  EXPECT_EQ(m.frame.weights[0], 0.0f);
  EXPECT_EQ(m.frame.weights[1], 1.0f);
}

TEST(WireFormat, ProfileNeutralAndRequestRoundTrip) {
  std::vector<uint8_t> bytes;
  const wire::Profile p = profile_of({5, 900, 17}, "mine");
  wire::encode_profile(4, 9, p, bytes);
  wire::Message m;
  ASSERT_EQ(wire::decode(bytes.data(), bytes.size(), m).reason, DropReason::none);
  EXPECT_EQ(m.envelope.type, wire::MessageType::profile);
  EXPECT_EQ(m.profile.indices, p.indices);
  EXPECT_EQ(m.profile.name, "mine");
  EXPECT_EQ(m.profile.id, p.id);

  std::vector<float> neutral(3 * 100);
  for (std::size_t i = 0; i < neutral.size(); ++i) neutral[i] = 0.001f * float(i);
  const auto chunks = wire::split_neutral(neutral.data(), 100);
  ASSERT_EQ(chunks.size(), 2u);
  wire::encode_neutral_chunk(4, 10, chunks[1], bytes);
  ASSERT_EQ(wire::decode(bytes.data(), bytes.size(), m).reason, DropReason::none);
  EXPECT_EQ(m.neutral.first_vertex, 80);
  EXPECT_EQ(m.neutral.total_vertices, 100);
  EXPECT_EQ(m.neutral.xyz, std::vector<float>(neutral.begin() + 240, neutral.end()));
  EXPECT_EQ(m.neutral.neutral_id, wire::neutral_id_of(neutral.data(), 100));

  wire::encode_request(4, 11, {wire::RequestKind::neutral, 0}, bytes);
  ASSERT_EQ(wire::decode(bytes.data(), bytes.size(), m).reason, DropReason::none);
  EXPECT_EQ(m.request.what, wire::RequestKind::neutral);
}

TEST(WireFormat, HostileDatagramsAreDroppedWithTheirReason) {
  std::vector<uint8_t> good;
  wire::encode_frame(make_frame(1, 10, 5), good);
  auto with = [&](auto edit) {
    std::vector<uint8_t> b = good;
    edit(b);
    return decode_reason(b);
  };
  EXPECT_EQ(decode_reason({}), DropReason::undersized);
  EXPECT_EQ(decode_reason(std::vector<uint8_t>(good.begin(), good.begin() + 15)), DropReason::undersized);
  EXPECT_EQ(decode_reason(std::vector<uint8_t>(1200, 0)), DropReason::oversized);
  EXPECT_EQ(with([](auto& b) { b[0] = 'X'; }), DropReason::bad_magic);
  EXPECT_EQ(with([](auto& b) { b[4] = 2; }), DropReason::incompatible_version);
  EXPECT_EQ(with([](auto& b) { b[4] = 0; }), DropReason::incompatible_version);
  EXPECT_EQ(with([](auto& b) { b[6] = 42; }), DropReason::unknown_type);
  EXPECT_EQ(with([](auto& b) { b.resize(30); }), DropReason::undersized);  // frame fixed part cut
  // The weights block claims more bytes than the datagram has: a lying length.
  EXPECT_EQ(with([](auto& b) { b[38] = 0xFF; b[39] = 0xFF; }), DropReason::bad_length);
  // The last block is cut short.
  EXPECT_EQ(with([](auto& b) { b.pop_back(); }), DropReason::bad_length);
  // A trailing partial block header.
  EXPECT_EQ(with([](auto& b) { b.push_back(1); }), DropReason::bad_length);
  // NaN capture time, unknown tracking state.
  EXPECT_EQ(with([](auto& b) {
              const double nan = std::numeric_limits<double>::quiet_NaN();
              std::memcpy(b.data() + 16, &nan, 8);
            }),
            DropReason::bad_value);
  EXPECT_EQ(with([](auto& b) { b[32] = 7; }), DropReason::bad_value);
  // A head pose whose quaternion is no rotation.
  Frame f = make_frame(1);
  f.head.rotation = {0, 0, 0, 3};
  std::vector<uint8_t> b;
  wire::encode_frame(f, b);
  EXPECT_EQ(decode_reason(b), DropReason::bad_value);
}

TEST(WireFormat, FramesNeedTheirWeightsBlockAndNoDuplicates) {
  std::vector<uint8_t> good;
  wire::encode_frame(make_frame(1), good);
  // Drop the weights block (header 16 + fixed 20, then 4 + 104 bytes).
  std::vector<uint8_t> b(good.begin(), good.begin() + 36);
  b.insert(b.end(), good.begin() + 36 + 108, good.end());
  EXPECT_EQ(decode_reason(b), DropReason::bad_length);
  // Twice the weights block.
  b = good;
  b.insert(b.end(), good.begin() + 36, good.begin() + 36 + 108);
  EXPECT_EQ(decode_reason(b), DropReason::bad_value);
}

TEST(WireFormat, ControlMessagesRejectLies) {
  std::vector<uint8_t> b;
  wire::encode_profile(1, 1, profile_of({3, 4, 5}), b);
  std::vector<uint8_t> lie = b;
  lie[20] = 200;  // count 200 > 150
  EXPECT_EQ(decode_reason(lie), DropReason::bad_value);
  lie = b;
  lie[20] = 4;  // one index more than present
  EXPECT_EQ(decode_reason(lie), DropReason::bad_length);
  lie = b;
  lie.back() ^= 1;  // the id no longer matches
  EXPECT_EQ(decode_reason(lie), DropReason::bad_value);

  std::vector<float> neutral(30, 0.01f);
  wire::encode_neutral_chunk(1, 1, wire::split_neutral(neutral.data(), 10)[0], b);
  lie = b;
  lie[22] = 9;  // first vertex 9 + 10 vertices > 10
  EXPECT_EQ(decode_reason(lie), DropReason::bad_value);
  lie = b;
  lie.resize(lie.size() - 1);
  EXPECT_EQ(decode_reason(lie), DropReason::bad_length);
  const float inf = std::numeric_limits<float>::infinity();
  lie = b;
  std::memcpy(lie.data() + 28, &inf, 4);
  EXPECT_EQ(decode_reason(lie), DropReason::bad_value);
}

TEST(WireFormat, EveryPrefixAndEveryByteFlipDecodesOrFailsCleanly) {
  // Under ASan this is an exhaustive out-of-bounds check on real messages.
  std::vector<std::vector<uint8_t>> messages(3);
  wire::encode_frame(make_frame(2, 20, 9), messages[0]);
  wire::encode_profile(1, 2, profile_of({1, 2, 3, 4}), messages[1]);
  std::vector<float> neutral(3 * 90, 0.02f);
  wire::encode_neutral_chunk(1, 3, wire::split_neutral(neutral.data(), 90)[0], messages[2]);
  wire::Message m;
  for (const auto& msg : messages) {
    for (std::size_t n = 0; n < msg.size(); ++n) {
      std::vector<uint8_t> prefix(msg.begin(), msg.begin() + static_cast<std::ptrdiff_t>(n));
      EXPECT_NE(wire::decode(prefix.data(), prefix.size(), m).reason, DropReason::none) << n;
    }
    for (std::size_t i = 0; i < msg.size(); ++i) {
      std::vector<uint8_t> flipped = msg;
      flipped[i] ^= 0xA5;
      wire::decode(flipped.data(), flipped.size(), m);
    }
  }
}
