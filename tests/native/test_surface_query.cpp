// Closest points on a mesh (geometry/surface_query.h): long triangles cut into pieces return
// what the whole triangles return, a moved tree what a new one finds, and slivers across a
// surface cost a bounded number of tree nodes a query, counted rather than timed.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "geometry/surface_query.h"

using softdeca::geometry::Cutting;
using softdeca::geometry::Points;
using softdeca::geometry::SurfacePoint;
using softdeca::geometry::SurfaceQuery;
using softdeca::geometry::Triangles;

namespace {
// A sphere of `rings` x `segments` quads, radius 0.1 (a head's size, metres).
void sphere(int rings, int segments, Points& v, Triangles& f) {
  v.resize(rings * segments + 2, 3);
  v.row(0) << 0, 0.1, 0;
  v.row(1) << 0, -0.1, 0;
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double polar = M_PI * (r + 1) / (rings + 1), around = 2 * M_PI * s / segments;
      v.row(2 + r * segments + s) << 0.1 * std::sin(polar) * std::cos(around), 0.1 * std::cos(polar), 0.1 * std::sin(polar) * std::sin(around);
    }
  std::vector<std::int32_t> t;
  const auto at = [&](int r, int s) { return 2 + r * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) {
    t.insert(t.end(), {0, at(0, s + 1), at(0, s)});
    t.insert(t.end(), {1, at(rings - 1, s), at(rings - 1, s + 1)});
    for (int r = 0; r + 1 < rings; ++r) t.insert(t.end(), {at(r, s), at(r, s + 1), at(r + 1, s + 1), at(r, s), at(r + 1, s + 1), at(r + 1, s)});
  }
  f = Eigen::Map<const Triangles>(t.data(), static_cast<Eigen::Index>(t.size() / 3), 3);
}

// `count` slivers: an edge of the mesh to a random vertex of it.
Triangles with_slivers(const Triangles& f, Eigen::Index vertices, int count) {
  std::mt19937 random(3);
  std::uniform_int_distribution<Eigen::Index> any_triangle(0, f.rows() - 1), any_vertex(0, vertices - 1);
  Triangles out(f.rows() + count, 3);
  out.topRows(f.rows()) = f;
  for (int i = 0; i < count; ++i) {
    const Eigen::Index t = any_triangle(random);
    out.row(f.rows() + i) << f(t, 0), f(t, 1), static_cast<std::int32_t>(any_vertex(random));
  }
  return out;
}

// Every vertex pushed 2 mm out and in: the queries a registration asks near a surface.
std::vector<Eigen::Vector3d> near_points(const Points& v) {
  std::vector<Eigen::Vector3d> p;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const Eigen::Vector3d x = v.row(i).transpose();
    p.push_back(x * (1 + 0.02));
    p.push_back(x * (1 - 0.02));
  }
  return p;
}

double visits_per_query(const SurfaceQuery& q, const std::vector<Eigen::Vector3d>& points) {
  std::size_t visits = 0;
  for (const Eigen::Vector3d& p : points) q.closest(p, 0.02, &visits);
  return static_cast<double>(visits) / static_cast<double>(points.size());
}
}  // namespace

TEST(SurfaceQuery, PiecesOfLongTrianglesFindWhatTheTrianglesFind) {
  std::mt19937 random(1);
  std::uniform_real_distribution<double> u(-1, 1);
  Points v(12, 3);
  for (Eigen::Index i = 0; i < v.rows(); ++i) v.row(i) << u(random), u(random), u(random);
  v.row(11) = 0.5 * (v.row(9) + v.row(10));  // a triangle with no area: three corners in a line
  Triangles f(5, 3);
  f << 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 0, 5, 9;
  Cutting cutting;
  cutting.piece_size = 0.1;
  const SurfaceQuery whole(v, f), cut(v, f, cutting);
  EXPECT_EQ(whole.entries(), 5u);
  EXPECT_GT(cut.entries(), 100u);
  EXPECT_EQ(cut.entries(), SurfaceQuery::entries_needed(v, f, cutting, 1u << 30));
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d p(u(random), u(random), u(random));
    const SurfacePoint a = whole.closest(p), b = cut.closest(p);
    ASSERT_GE(b.triangle, 0);
    EXPECT_NEAR(std::sqrt(a.squared_distance), std::sqrt(b.squared_distance), 1e-6);
    // The piece's weights are the triangle's: they give back the point found.
    Eigen::Vector3d back = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) back += b.bary[k] * v.row(f(b.triangle, k)).transpose();
    EXPECT_NEAR((back - b.point).norm(), 0, 1e-5);
    EXPECT_NEAR(b.bary.sum(), 1, 1e-5);
    EXPECT_GE(b.bary.minCoeff(), -1e-6);
  }
  // Cut only where asked: a region away from every triangle cuts none.
  cutting.lo = Eigen::Vector3d::Constant(5);
  cutting.hi = Eigen::Vector3d::Constant(6);
  EXPECT_EQ(SurfaceQuery(v, f, cutting).entries(), 5u);
}

TEST(SurfaceQuery, AMovedTreeFindsWhatANewTreeFinds) {
  Points v;
  Triangles f;
  sphere(20, 40, v, f);
  const Triangles all = with_slivers(f, v.rows(), 500);
  Cutting cutting;
  cutting.piece_size = 0.01;
  SurfaceQuery moved(v, all, cutting);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Points v2 = (v * turn.transpose()).rowwise() + Eigen::RowVector3d(0.01, -0.02, 0.03);
  moved.move(v2);
  const SurfaceQuery fresh(v2, all, cutting);
  for (const Eigen::Vector3d& p : near_points(v2)) {
    const SurfacePoint a = moved.closest(p, 0.02), b = fresh.closest(p, 0.02);
    ASSERT_EQ(a.triangle >= 0, b.triangle >= 0);
    EXPECT_NEAR(a.squared_distance, b.squared_distance, 1e-9);
  }
}

// The work is counted in tree nodes visited, so the bound holds on any machine.
TEST(SurfaceQuery, SliversAcrossAHeadCostABoundedNumberOfVisits) {
  Points v;
  Triangles f;
  sphere(50, 100, v, f);  // 5,002 vertices, 10,000 triangles
  const Triangles all = with_slivers(f, v.rows(), 20000);
  const std::vector<Eigen::Vector3d> points = near_points(v);
  const double plain = visits_per_query(SurfaceQuery(v, f), points);
  const double uncut = visits_per_query(SurfaceQuery(v, all), points);
  Cutting cutting;
  cutting.piece_size = 0.01;
  const SurfaceQuery cut(v, all, cutting);
  const double pieces = visits_per_query(cut, points);
  // Uncut, every query near the head tests most of the 20,000 slivers; cut into pieces of 1 cm
  // (a few hundred thousand), a few times the head's own.
  EXPECT_GT(uncut, 50 * plain) << plain << " " << uncut;
  EXPECT_LT(pieces, 10 * plain) << plain << " " << pieces;
  EXPECT_LT(cut.entries(), static_cast<std::size_t>(all.rows()) + 1000000);
}
