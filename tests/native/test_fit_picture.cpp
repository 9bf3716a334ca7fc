// The fit's picture (plugin/cli/fit_picture.h) and the landmarks carried onto a user's surface
// (surface_points.h).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "fit_picture.h"
#include "surface_points.h"

using namespace softdeca::cli;

namespace {
// An axis-aligned box as 8 corners and 12 triangles.
struct Box {
  std::vector<float> vertices;
  std::vector<std::int32_t> triangles = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                         2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  Box(const float lo[3], const float hi[3]) {
    for (int i = 0; i < 8; ++i) vertices.insert(vertices.end(), {(i & 1) ? hi[0] : lo[0], (i & 2) ? hi[1] : lo[1], (i & 4) ? hi[2] : lo[2]});
  }
  PictureMesh mesh() const { return {vertices.data(), 8, triangles.data(), 12}; }
};

const std::uint8_t* pixel(const Picture& p, std::size_t x, std::size_t y) { return &p.rgb[3 * (y * p.width + x)]; }
bool orange(const std::uint8_t* c) { return c[0] > c[1] + 40 && c[1] > c[2]; }
bool grey(const std::uint8_t* c) { return c[0] == c[1] && c[1] == c[2] && c[0] < 250; }
}  // namespace

TEST(FitPicture, ShowsTheTemplateInColourOnTheGreyAvatarFromTheFrontAndTheSide) {
  const float body_lo[3] = {-1, -1, -1}, body_hi[3] = {1, 1, 1};
  const float face_lo[3] = {-0.5f, -0.5f, 0.9f}, face_hi[3] = {0.5f, 0.5f, 1.1f};  // sticks out of the front
  const Box body(body_lo, body_hi), face(face_lo, face_hi);
  const PictureAxes axes{{1, 0, 0}, {0, 1, 0}, {0, 0, 2}};
  const std::size_t n = 100;
  const Picture p = draw_fit(body.mesh(), face.mesh(), axes, n);
  ASSERT_EQ(p.width, 2 * n);
  ASSERT_EQ(p.height, n);
  EXPECT_TRUE(orange(pixel(p, n / 2, n / 2))) << "front: the template in the middle";
  EXPECT_TRUE(grey(pixel(p, 2, 2))) << "front: the body around it (framed on the template with a margin)";
  // Side, from the subject's left: the face points to the picture's left, the template's part
  // in front of the body shows.
  bool side_orange = false, side_grey = false;
  for (std::size_t x = n + 1; x < 2 * n; ++x) {
    side_orange = side_orange || orange(pixel(p, x, n / 2));
    side_grey = side_grey || grey(pixel(p, x, n / 2));
  }
  EXPECT_TRUE(side_orange);
  EXPECT_TRUE(side_grey);
  // Template points without triangles are drawn as dots.
  const PictureMesh dots{face.vertices.data(), 8, nullptr, 0};
  const Picture d = draw_fit(body.mesh(), dots, axes, n);
  EXPECT_FALSE(orange(pixel(d, n / 2, n / 2)));
  const PictureAxes zero{{0, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_THROW(draw_fit(body.mesh(), face.mesh(), zero, n), std::invalid_argument);
}

TEST(SurfacePoints, RideOnTheNearestPointOfTheSurface) {
  const std::vector<float> rest = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5};
  const std::vector<std::int32_t> triangles = {0, 1, 2};
  const std::vector<float> points = {0.25f, 0.25f, 0.5f, 2, -1, 0};  // above the triangle; beyond a corner
  const SurfacePoints on(rest.data(), 4, triangles, points.data(), 2);
  EXPECT_NEAR(on.max_distance(), std::sqrt(2.0), 1e-6);
  std::vector<float> moved = rest;
  for (std::size_t i = 0; i < 3; ++i) moved[3 * i + 2] += 1;
  std::vector<float> out(6);
  on.evaluate(moved.data(), out.data());
  EXPECT_NEAR(out[0], 0.25f, 1e-6);
  EXPECT_NEAR(out[1], 0.25f, 1e-6);
  EXPECT_NEAR(out[2], 1.0f, 1e-6);
  EXPECT_NEAR(out[3], 1.0f, 1e-6);  // the corner (1, 0) it was nearest to
  EXPECT_NEAR(out[4], 0.0f, 1e-6);
  EXPECT_THROW(SurfacePoints(rest.data(), 4, {}, points.data(), 2), std::invalid_argument);
}
