// Third-party formats into the canonical frame: Live Link Face's packet and CSV takes (with
// the real takes of the data folder), its timecode, iFacialMocap's text, and the angle conventions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/error.h"
#include "recording/livelinkface_csv.h"
#include "recording/timecode.h"
#include "stream/arkit_names.h"
#include "stream/ifacialmocap_packet.h"
#include "stream/livelinkface_layout.h"
#include "stream/livelinkface_packet.h"
#include "stream/rotation.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::stream;
using test::make_frame;

TEST(ArkitNames, CanonicalOrderIsAlphabetical) {
  EXPECT_STREQ(blendshape_name(0), "browDownLeft");
  EXPECT_STREQ(blendshape_name(24), "jawOpen");
  EXPECT_STREQ(blendshape_name(51), "tongueOut");
  EXPECT_EQ(blendshape_name(52), nullptr);
  for (std::size_t i = 1; i < kBlendshapeCount; ++i)
    EXPECT_LT(std::string(blendshape_name(i - 1)), std::string(blendshape_name(i)));
  EXPECT_EQ(blendshape_index("EyeBlinkLeft"), -1);
  EXPECT_EQ(blendshape_index("EyeBlinkLeft", true), 8);
}

TEST(LiveLinkFace, ValueOrderMapsOntoEveryCanonicalShapeOnce) {
  std::vector<int> seen(kBlendshapeCount, 0);
  for (std::size_t i = 0; i < livelinkface::kHeadYaw; ++i) {
    const int c = livelinkface::canonical_index(i);
    ASSERT_GE(c, 0) << livelinkface::value_name(i);
    ++seen[static_cast<std::size_t>(c)];
  }
  for (int n : seen) EXPECT_EQ(n, 1);
  EXPECT_EQ(livelinkface::canonical_index(15), blendshape_index("jawLeft"));  // Epic's order: JawLeft 15
  EXPECT_EQ(livelinkface::canonical_index(52), -1);                           // HeadYaw
}

TEST(LiveLinkFace, PacketRoundTripsAndKnowsItsSession) {
  Frame f = make_frame(5);
  f.capture_time = 60483.123;
  livelinkface::PacketInfo info;
  info.device_id = "E3F1-device";
  info.subject = "iPhone";
  std::vector<uint8_t> bytes;
  livelinkface::encode_packet(f, info, bytes);
  EXPECT_EQ(bytes.size(), 1 + 4 + 11 + 4 + 6 + 16 + 1 + 61 * 4u);
  EXPECT_EQ(bytes[0], 6);
  Frame g;
  livelinkface::PacketInfo back;
  ASSERT_EQ(livelinkface::decode_packet(bytes.data(), bytes.size(), g, back).reason, DropReason::none);
  EXPECT_EQ(back.device_id, "E3F1-device");
  EXPECT_EQ(back.subject, "iPhone");
  EXPECT_EQ(g.session_id, livelinkface::session_id_of("E3F1-device", "iPhone"));
  EXPECT_FALSE(g.has_sequence);
  EXPECT_NEAR(g.capture_time, 60483.123, 1e-6);
  for (std::size_t i = 0; i < kBlendshapeCount; ++i) EXPECT_EQ(g.weights[i], f.weights[i]);
  ASSERT_TRUE(g.has_head && g.has_eyes);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(g.head.rotation[k], f.head.rotation[k], 1e-6);
  EXPECT_EQ(g.head.position[2], 0.0f);  // the format has no position
}

TEST(LiveLinkFace, HostilePacketsAreDroppedWithTheirReason) {
  std::vector<uint8_t> good;
  livelinkface::PacketInfo info;
  livelinkface::encode_packet(make_frame(1), info, good);
  Frame f;
  livelinkface::PacketInfo i2;
  auto reason = [&](std::vector<uint8_t> b) { return livelinkface::decode_packet(b.data(), b.size(), f, i2).reason; };
  EXPECT_EQ(reason({}), DropReason::undersized);
  EXPECT_EQ(reason({7}), DropReason::incompatible_version);
  std::vector<uint8_t> b = good;
  b[4] = 200;  // device id length 200 > the packet
  EXPECT_EQ(reason(b), DropReason::bad_length);
  b = good;
  b[1] = 0x80;  // negative length
  EXPECT_EQ(reason(b), DropReason::bad_length);
  b = good;
  b.resize(b.size() - 3);
  EXPECT_EQ(reason(b), DropReason::bad_length);
  b = good;
  b.resize(b.size() - 244);
  b.back() = 30;  // 30 values: neither 0 nor 61
  EXPECT_EQ(reason(b), DropReason::bad_length);
  EXPECT_EQ(reason(std::vector<uint8_t>(3000, 6)), DropReason::oversized);
  for (std::size_t n = 0; n < good.size(); ++n)
    EXPECT_NE(reason(std::vector<uint8_t>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n))),
              DropReason::none);
}

TEST(LiveLinkFace, TimecodesParseAndFormat) {
  double s = 0;
  ASSERT_TRUE(recording::parse_timecode("16:48:39:43.245", 60, s));
  EXPECT_NEAR(s, 16 * 3600 + 48 * 60 + 39 + 43.245 / 60, 1e-9);
  EXPECT_EQ(recording::format_timecode(s, 60), "16:48:39:43.245");
  ASSERT_TRUE(recording::parse_timecode("00:00:01:02", 30, s));
  EXPECT_NEAR(s, 1 + 2.0 / 30, 1e-12);
  EXPECT_EQ(recording::format_timecode(59.9999999, 60), "00:01:00:00.000");  // rounding carries
  for (const char* bad : {"", "1:2:3", "24:00:00:00.000", "00:60:00:00", "00:00:00:60.000", "00:00:00:01.", "aa:00:00:00",
                          "00:00:00:01.2345", "00:00:00:01x"})
    EXPECT_FALSE(recording::parse_timecode(bad, 60, s)) << bad;
}

TEST(LiveLinkFace, RealTakesParseWithFaceLostRowsSkippedAndCounted) {
  struct Take {
    const char* file;
    std::size_t rows, lost;
  };
  for (const Take t : {Take{"S88-001.csv", 1939, 277}, Take{"apfel.csv", 1926, 35}, Take{"facial.csv", 1913, 0}}) {
    SCOPED_TRACE(t.file);
    const auto take = recording::read_livelinkface_csv(test::takes_dir() + t.file, 60);
    EXPECT_EQ(take.rows, t.rows);
    EXPECT_EQ(take.face_lost_rows, t.lost);
    EXPECT_EQ(take.malformed_rows, 0u);
    EXPECT_EQ(take.frames.size(), t.rows - t.lost);
    for (std::size_t i = 1; i < take.frames.size(); ++i) EXPECT_GT(take.frames[i].capture_time, take.frames[i - 1].capture_time);
  }
  // Parsed by name: S88's first row has EyeLookOutLeft 0.4479776323 and JawRight 0.0673732013.
  const auto take = recording::read_livelinkface_csv(test::takes_dir() + "S88-001.csv", 60);
  EXPECT_EQ(take.frames[0].weights[static_cast<std::size_t>(blendshape_index("eyeLookOutLeft"))], 0.4479776323f);
  EXPECT_EQ(take.frames[0].weights[static_cast<std::size_t>(blendshape_index("jawRight"))], 0.0673732013f);
}

TEST(LiveLinkFace, CsvColumnsAreFoundByNameInEitherSpelling) {
  std::string header = "Timecode,BlendshapeCount";
  std::string row = "01:02:03:04.500,61";
  // Columns in reverse packet order: a reader that assumed an order would scramble them.
  for (int i = 60; i >= 0; --i) {
    header += std::string(",") + livelinkface::value_name(static_cast<std::size_t>(i));
    row += "," + std::to_string(i < 52 ? i / 100.0 : 0.0);
  }
  const auto take = recording::parse_livelinkface_csv(header + "\r\n" + row + "\r\n01:02:03:06.000,0\r\n,,,\r\n", 60);
  ASSERT_EQ(take.frames.size(), 1u);
  EXPECT_EQ(take.face_lost_rows, 1u);
  EXPECT_EQ(take.malformed_rows, 1u);
  for (std::size_t i = 0; i < 52; ++i)
    EXPECT_FLOAT_EQ(take.frames[0].weights[static_cast<std::size_t>(livelinkface::canonical_index(i))], float(i) / 100.0f);
  EXPECT_THROW(recording::parse_livelinkface_csv("Timecode,BlendShapeCount,EyeBlinkLeft\n", 60), Error);
}

TEST(LiveLinkFace, CsvRoundTripKeepsEveryRow) {
  const auto take = recording::read_livelinkface_csv(test::takes_dir() + "apfel.csv", 60);
  const std::string csv = recording::format_livelinkface_csv(take.frames, 60);
  const auto again = recording::parse_livelinkface_csv(csv, 60);
  ASSERT_EQ(again.frames.size(), take.frames.size());
  EXPECT_EQ(again.face_lost_rows, 0u);
  for (std::size_t i = 0; i < take.frames.size(); ++i) {
    EXPECT_NEAR(again.frames[i].capture_time, take.frames[i].capture_time, 1e-9);
    EXPECT_EQ(again.frames[i].weights, take.frames[i].weights) << i;
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(again.frames[i].left_eye.rotation[k], take.frames[i].left_eye.rotation[k], 1e-6);
  }
}

TEST(IFacialMocap, ParsesBothSeparatorsTransformsAndMissingNames) {
  const std::string text =
      "mouthSmile_R-25|eyeBlink_L-100|jawOpen-40|mouthLeft-3|trackingStatus-1|34903,-1.666|"
      "=head#-21.5,6.0,-6.6,-0.03,-0.1,-0.65|rightEye#6.0,2.4,0.25|leftEye#6.0,-1.6,-0.17|";
  for (char sep : {'-', '&'}) {
    std::string t = text;
    if (sep == '&')
      for (const char* name : {"mouthSmile_R", "eyeBlink_L", "jawOpen", "mouthLeft", "trackingStatus"})
        t[t.find(name) + std::string(name).size()] = '&';
    Frame f;
    ifacialmocap::Presence present;
    ASSERT_EQ(ifacialmocap::decode_packet(reinterpret_cast<const uint8_t*>(t.data()), t.size(), f, present).reason,
              DropReason::none);
    EXPECT_FLOAT_EQ(f.weights[static_cast<std::size_t>(blendshape_index("mouthSmileRight"))], 0.25f);
    EXPECT_FLOAT_EQ(f.weights[static_cast<std::size_t>(blendshape_index("eyeBlinkLeft"))], 1.0f);
    EXPECT_FLOAT_EQ(f.weights[static_cast<std::size_t>(blendshape_index("mouthLeft"))], 0.03f);
    EXPECT_TRUE(present[static_cast<std::size_t>(blendshape_index("jawOpen"))]);
    EXPECT_FALSE(present[static_cast<std::size_t>(blendshape_index("tongueOut"))]);
    ASSERT_TRUE(f.has_head && f.has_eyes);
    EXPECT_FLOAT_EQ(f.head.position[2], 0.65f);  // Unity's z mirrored
    const auto back = unity_euler_degrees_from_quaternion(f.head.rotation);
    EXPECT_NEAR(back[0], -21.5, 1e-4);
    EXPECT_NEAR(back[1], 6.0, 1e-4);
    EXPECT_NEAR(back[2], -6.6, 1e-4);
  }
}

TEST(IFacialMocap, EncoderRoundTripsToIntegerPercent) {
  const Frame f = make_frame(8);
  const std::string text = ifacialmocap::encode_packet(f);
  Frame g;
  ifacialmocap::Presence present;
  ASSERT_EQ(ifacialmocap::decode_packet(reinterpret_cast<const uint8_t*>(text.data()), text.size(), g, present).reason,
            DropReason::none);
  for (std::size_t i = 0; i < kBlendshapeCount; ++i) {
    EXPECT_TRUE(present[i]) << ifacialmocap::wire_name(i);
    EXPECT_NEAR(g.weights[i], f.weights[i], 0.005 + 1e-6);
  }
  EXPECT_EQ(ifacialmocap::wire_name(static_cast<std::size_t>(blendshape_index("jawLeft"))), "jawLeft");
  EXPECT_EQ(ifacialmocap::wire_name(static_cast<std::size_t>(blendshape_index("browDownLeft"))), "browDown_L");
}

TEST(IFacialMocap, HostileTextIsDropped) {
  Frame f;
  ifacialmocap::Presence p;
  auto reason = [&](const std::string& t) {
    return ifacialmocap::decode_packet(reinterpret_cast<const uint8_t*>(t.data()), t.size(), f, p).reason;
  };
  EXPECT_EQ(reason(""), DropReason::undersized);
  EXPECT_EQ(reason("hello world"), DropReason::bad_magic);
  EXPECT_EQ(reason(std::string("jawOpen-4\0", 10)), DropReason::bad_magic);
  EXPECT_EQ(reason("jawOpen-abc|"), DropReason::bad_value);
  EXPECT_EQ(reason("jawOpen-1e400|"), DropReason::bad_value);
  EXPECT_EQ(reason("jawOpen-5|=head#1,2,3|"), DropReason::bad_value);
  EXPECT_EQ(reason(std::string(9000, 'a')), DropReason::oversized);
  EXPECT_EQ(reason("unknownShape-5|jawOpen-50"), DropReason::none);
}

TEST(Rotation, ConventionsRoundTrip) {
  for (double yaw : {-1.2, 0.0, 0.7})
    for (double pitch : {-1.0, 0.3})
      for (double roll : {-0.4, 0.9}) {
        const auto q = quaternion_from_yaw_pitch_roll(yaw, pitch, roll);
        const auto back = yaw_pitch_roll_from_quaternion(q);
        EXPECT_NEAR(back[0], yaw, 1e-6);
        EXPECT_NEAR(back[1], pitch, 1e-6);
        EXPECT_NEAR(back[2], roll, 1e-6);
      }
  // Yaw alone turns about +Y: (0, sin(y/2), 0, cos(y/2)).
  const auto q = quaternion_from_yaw_pitch_roll(0.5, 0, 0);
  EXPECT_NEAR(q[1], std::sin(0.25), 1e-7);
  EXPECT_NEAR(q[3], std::cos(0.25), 1e-7);
  // Unity's left-handed yaw becomes the opposite turn about ARKit's +Y.
  const auto u = quaternion_from_unity_euler_degrees(0, 30, 0);
  EXPECT_NEAR(u[1], -std::sin(std::acos(-1.0) / 12), 1e-7);
}
