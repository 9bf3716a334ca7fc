#include <gtest/gtest.h>

#include <random>

#include "geometry/tet_mesh.h"

using namespace softdeca::geometry;

namespace {
// A unit cube split into six positive tets around the diagonal 0-6 (Kuhn triangulation).
void unit_cube(Points& v, Tets& t, double scale = 1.0) {
  v.resize(8, 3);
  for (int i = 0; i < 8; ++i) v.row(i) << (i & 1) * scale, ((i >> 1) & 1) * scale, ((i >> 2) & 1) * scale;
  t.resize(6, 4);
  t << 0, 1, 3, 7, 0, 1, 7, 5, 0, 5, 7, 4, 0, 3, 2, 7, 0, 2, 6, 7, 0, 6, 4, 7;
}
}  // namespace

TEST(TetMesh, VolumesArePositiveAndSumToTheCube) {
  Points v;
  Tets t;
  unit_cube(v, t, 2.0);
  const Eigen::VectorXd vol = tet_signed_volumes(v, t);
  for (int i = 0; i < vol.size(); ++i) EXPECT_GT(vol[i], 0.0) << "tet " << i;
  EXPECT_NEAR(vol.sum(), 8.0, 1e-12);
}

TEST(TetMesh, FlippedTetHasNegativeVolume) {
  Points v;
  Tets t;
  unit_cube(v, t);
  std::swap(t(0, 1), t(0, 2));
  EXPECT_LT(tet_signed_volumes(v, t)[0], 0.0);
}

TEST(TetMesh, EmbeddedPointsAreReproducedByTheirCoordinates) {
  Points v;
  Tets t;
  unit_cube(v, t);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points p(500, 3);
  for (int i = 0; i < p.rows(); ++i) p.row(i) << u(rng), u(rng), u(rng);
  const Embedding e = embed_points(v, t, p);
  for (int i = 0; i < p.rows(); ++i) {
    ASSERT_GE(e.tet[i], 0);
    EXPECT_EQ(e.outside[i], 0.0);
    EXPECT_GE(e.bary.row(i).minCoeff(), -1e-9);
    EXPECT_NEAR(e.bary.row(i).sum(), 1.0, 1e-12);
    Eigen::RowVector3d q = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 4; ++k) q += e.bary(i, k) * v.row(t(e.tet[i], k));
    EXPECT_LT((q - p.row(i)).norm(), 1e-12);
  }
}

TEST(TetMesh, OutsidePointGetsNearestTetAndItsDistance) {
  Points v;
  Tets t;
  unit_cube(v, t);
  Points p(2, 3);
  p << 0.5, 0.5, 1.25,  // 0.25 above the top face
      3.0, 0.5, 0.5;    // 2.0 beyond the x = 1 face
  const Embedding e = embed_points(v, t, p);
  EXPECT_NEAR(e.outside[0], 0.25, 1e-12);
  EXPECT_NEAR(e.outside[1], 2.0, 1e-12);
  for (int i = 0; i < 2; ++i) {
    EXPECT_LT(e.bary.row(i).minCoeff(), 0.0);  // extrapolated
    Eigen::RowVector3d q = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 4; ++k) q += e.bary(i, k) * v.row(t(e.tet[i], k));
    EXPECT_LT((q - p.row(i)).norm(), 1e-9);
  }
}

TEST(TetMesh, PointTetDistanceIsZeroInsideAndEuclideanOutside) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(0, 0, 1);
  EXPECT_EQ(point_tet_distance({0.1, 0.1, 0.1}, a, b, c, d), 0.0);
  EXPECT_NEAR(point_tet_distance({-1, 0, 0}, a, b, c, d), 1.0, 1e-12);
  EXPECT_NEAR(point_tet_distance({1, 1, 1}, a, b, c, d), (Eigen::Vector3d(1, 1, 1) - Eigen::Vector3d::Constant(1.0 / 3)).norm(), 1e-12);
}
