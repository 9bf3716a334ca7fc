#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "geometry/cotan.h"

using namespace softdeca::geometry;

namespace {
// Icosahedron refined `levels` times and projected on the unit sphere.
void sphere(int levels, TriPoints& v, Triangles& f) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Eigen::Vector3i> tri = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                      {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                      {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                      {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back((p[a] + p[b]) / 2);
      return mid[key] = static_cast<int>(p.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (auto& x : tri) {
      int a = midpoint(x[0], x[1]), b = midpoint(x[1], x[2]), c = midpoint(x[2], x[0]);
      next.insert(next.end(), {{x[0], a, c}, {x[1], b, a}, {x[2], c, b}, {a, b, c}});
    }
    tri = next;
  }
  v.resize(static_cast<Eigen::Index>(p.size()), 3);
  for (std::size_t i = 0; i < p.size(); ++i) v.row(static_cast<Eigen::Index>(i)) = p[i].normalized().transpose();
  f.resize(static_cast<Eigen::Index>(tri.size()), 3);
  for (std::size_t i = 0; i < tri.size(); ++i) f.row(static_cast<Eigen::Index>(i)) = tri[i].transpose();
}
}  // namespace

TEST(Cotan, LaplacianIsSymmetricWithZeroRowSums) {
  TriPoints v;
  Triangles f;
  sphere(2, v, f);
  const auto L = cotan_laplacian(v, f);
  const Eigen::MatrixXd D = Eigen::MatrixXd(L);
  EXPECT_LT((D - D.transpose()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((D * Eigen::VectorXd::Ones(v.rows())).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Cotan, MeanCurvatureOfUnitSphereIsTwoOverRadius) {
  // M^-1 L x approximates the mean-curvature normal -2H n = -2 n on the unit sphere.
  TriPoints v;
  Triangles f;
  sphere(4, v, f);
  const auto L = cotan_laplacian(v, f);
  const Eigen::VectorXd A = voronoi_areas(v, f);
  const Eigen::MatrixXd Lx = L * Eigen::MatrixXd(v);
  double worst = 0;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const Eigen::Vector3d hn = Lx.row(i).transpose() / A[i];
    worst = std::max(worst, std::abs(hn.norm() - 2.0));
    EXPECT_LT(hn.normalized().dot(v.row(i).transpose()), -0.99);  // points inward
  }
  EXPECT_LT(worst, 0.05);
}

TEST(Cotan, VoronoiAreasSumToSurfaceArea) {
  TriPoints v;
  Triangles f;
  sphere(3, v, f);
  double area = 0;
  for (Eigen::Index t = 0; t < f.rows(); ++t)
    area += 0.5 * (v.row(f(t, 1)) - v.row(f(t, 0))).cross(v.row(f(t, 2)) - v.row(f(t, 0))).norm();
  EXPECT_NEAR(voronoi_areas(v, f).sum(), area, 1e-10);
  EXPECT_NEAR(area, 4 * M_PI, 0.05 * 4 * M_PI);
}
