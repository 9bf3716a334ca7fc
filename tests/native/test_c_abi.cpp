// The C ABI: version, errors, and the geometry entry points with good and hostile input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "softdeca/softdeca.h"

namespace {
// One positive tet and the cube corner points.
const std::vector<float> kVerts = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
const std::vector<int32_t> kTet = {0, 1, 2, 3};
}  // namespace

TEST(CAbi, VersionIsSemantic) {
  const std::string v = softdeca_version();
  EXPECT_EQ(std::count(v.begin(), v.end(), '.'), 2) << v;
}

TEST(CAbi, StatusNamesCoverEveryCode) {
  for (int s = SOFTDECA_OK; s <= SOFTDECA_ERROR_INTERNAL; ++s)
    EXPECT_STRNE(softdeca_status_name(static_cast<softdeca_status>(s)), "unknown status");
}

TEST(CAbi, EmbedsAPointAndClearsTheError) {
  const float p[3] = {0.1f, 0.2f, 0.3f};
  int32_t tet = -1;
  float bary[4], outside = -1;
  ASSERT_EQ(softdeca_embed_points(kVerts.data(), 4, kTet.data(), 1, p, 1, &tet, bary, &outside), SOFTDECA_OK);
  EXPECT_STREQ(softdeca_last_error(), "");
  EXPECT_EQ(tet, 0);
  EXPECT_NEAR(bary[0], 0.4f, 1e-6);
  EXPECT_NEAR(bary[1], 0.1f, 1e-6);
  EXPECT_NEAR(bary[2], 0.2f, 1e-6);
  EXPECT_NEAR(bary[3], 0.3f, 1e-6);
  EXPECT_EQ(outside, 0.0f);
}

TEST(CAbi, RejectsNullsWithAMessage) {
  int32_t tet;
  float bary[4];
  const float p[3] = {0, 0, 0};
  EXPECT_EQ(softdeca_embed_points(nullptr, 4, kTet.data(), 1, p, 1, &tet, bary, nullptr),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(softdeca_last_error()).find("vertices is null"), std::string::npos);
  EXPECT_EQ(softdeca_embed_points(kVerts.data(), 4, kTet.data(), 1, p, 1, nullptr, bary, nullptr),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_compute_tet_volumes(kVerts.data(), 4, kTet.data(), 1, nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
}

TEST(CAbi, RejectsNonFiniteInputAndLeavesOutputsUntouched) {
  std::vector<float> bad = kVerts;
  bad[4] = std::nanf("");
  float vol = 123.0f;
  EXPECT_EQ(softdeca_compute_tet_volumes(bad.data(), 4, kTet.data(), 1, &vol), SOFTDECA_ERROR_NON_FINITE);
  EXPECT_EQ(vol, 123.0f);
  EXPECT_NE(std::string(softdeca_last_error()).find("vertices[4]"), std::string::npos);
  const float p[3] = {INFINITY, 0, 0};
  int32_t tet = 77;
  float bary[4] = {9, 9, 9, 9};
  EXPECT_EQ(softdeca_embed_points(kVerts.data(), 4, kTet.data(), 1, p, 1, &tet, bary, nullptr),
            SOFTDECA_ERROR_NON_FINITE);
  EXPECT_EQ(tet, 77);
  EXPECT_EQ(bary[0], 9.0f);
}

TEST(CAbi, RejectsOutOfRangeIndicesAndTooFewVertices) {
  const std::vector<int32_t> bad = {0, 1, 2, 4};
  float vol;
  EXPECT_EQ(softdeca_compute_tet_volumes(kVerts.data(), 4, bad.data(), 1, &vol), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(softdeca_last_error()).find("tets[3] = 4"), std::string::npos);
  const std::vector<int32_t> negative = {0, -1, 2, 3};
  EXPECT_EQ(softdeca_compute_tet_volumes(kVerts.data(), 4, negative.data(), 1, &vol), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_compute_tet_volumes(kVerts.data(), 3, kTet.data(), 1, &vol), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_compute_tet_volumes(kVerts.data(), 4, kTet.data(), 0, &vol), SOFTDECA_ERROR_INVALID_ARGUMENT);
}

TEST(CAbi, LastErrorIsPerThread) {
  float vol;
  ASSERT_NE(softdeca_compute_tet_volumes(nullptr, 4, kTet.data(), 1, &vol), SOFTDECA_OK);
  std::string other;
  std::thread([&] { other = softdeca_last_error(); }).join();
  EXPECT_EQ(other, "");
  EXPECT_NE(std::string(softdeca_last_error()), "");
}

TEST(CAbi, TetVolume) {
  float vol = 0;
  ASSERT_EQ(softdeca_compute_tet_volumes(kVerts.data(), 4, kTet.data(), 1, &vol), SOFTDECA_OK);
  EXPECT_NEAR(vol, 1.0f / 6.0f, 1e-7);
}
