#include "geometry/tet_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "geometry/grid_ring.h"

namespace softdeca::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

Vec3 row(const Points& m, int32_t i) { return m.row(i).transpose(); }

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Uniform grid of cells, each listing the tets whose bounding box overlaps it.
struct TetGrid {
  Vec3 lo, cell;
  std::array<int, 3> n{};
  std::vector<int32_t> start, items;  // CSR: tets of cell k are items[start[k] .. start[k+1])

  std::array<int, 3> cell_of(const Vec3& p) const {
    std::array<int, 3> c{};
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>(std::floor((p[k] - lo[k]) / cell[k])), 0, n[k] - 1);
    return c;
  }
  int index(int i, int j, int k) const { return (k * n[1] + j) * n[0] + i; }
};

TetGrid build_grid(const Points& v, const Tets& t) {
  TetGrid g;
  g.lo = v.colwise().minCoeff().transpose();
  const Vec3 hi = v.colwise().maxCoeff().transpose();
  const Vec3 ext = (hi - g.lo).cwiseMax(1e-9);
  // About two tets per cell on average.
  const double cells = std::max<double>(1.0, t.rows() / 2.0);
  const double h = std::cbrt(ext.prod() / cells);
  for (int k = 0; k < 3; ++k) {
    g.n[k] = std::clamp(static_cast<int>(std::ceil(ext[k] / h)), 1, 512);
    g.cell[k] = ext[k] / g.n[k];
  }
  const std::size_t ncell = static_cast<std::size_t>(g.n[0]) * g.n[1] * g.n[2];
  std::vector<std::array<int, 6>> ranges(t.rows());
  std::vector<int32_t> count(ncell + 1, 0);
  for (Eigen::Index e = 0; e < t.rows(); ++e) {
    Vec3 blo = row(v, t(e, 0)), bhi = blo;
    for (int c = 1; c < 4; ++c) {
      blo = blo.cwiseMin(row(v, t(e, c)));
      bhi = bhi.cwiseMax(row(v, t(e, c)));
    }
    const auto a = g.cell_of(blo), b = g.cell_of(bhi);
    ranges[e] = {a[0], a[1], a[2], b[0], b[1], b[2]};
    for (int k = a[2]; k <= b[2]; ++k)
      for (int j = a[1]; j <= b[1]; ++j)
        for (int i = a[0]; i <= b[0]; ++i) ++count[g.index(i, j, k) + 1];
  }
  for (std::size_t c = 0; c < ncell; ++c) count[c + 1] += count[c];
  g.start = count;
  g.items.resize(count[ncell]);
  std::vector<int32_t> fill(count.begin(), count.end() - 1);
  for (Eigen::Index e = 0; e < t.rows(); ++e) {
    const auto& r = ranges[e];
    for (int k = r[2]; k <= r[5]; ++k)
      for (int j = r[1]; j <= r[4]; ++j)
        for (int i = r[0]; i <= r[3]; ++i) g.items[fill[g.index(i, j, k)]++] = static_cast<int32_t>(e);
  }
  return g;
}

}  // namespace

Eigen::VectorXd tet_signed_volumes(const Points& v, const Tets& t) {
  Eigen::VectorXd vol(t.rows());
  for (Eigen::Index e = 0; e < t.rows(); ++e) {
    const Vec3 a = row(v, t(e, 0));
    vol[e] = (row(v, t(e, 1)) - a).dot((row(v, t(e, 2)) - a).cross(row(v, t(e, 3)) - a)) / 6.0;
  }
  return vol;
}

Eigen::Vector4d tet_barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                const Vec3& d) {
  Eigen::Matrix3d m;
  m.col(0) = b - a;
  m.col(1) = c - a;
  m.col(2) = d - a;
  const double det = m.determinant();
  if (!(std::abs(det) > 1e-30)) return Eigen::Vector4d::Constant(std::nan(""));
  const Vec3 x = m.inverse() * (p - a);
  return {1.0 - x.sum(), x[0], x[1], x[2]};
}

double point_tet_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                          const Vec3& d) {
  const Eigen::Vector4d l = tet_barycentric(p, a, b, c, d);
  if (l.minCoeff() >= 0) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  const std::array<std::array<const Vec3*, 3>, 4> faces{
      {{&a, &b, &c}, {&a, &b, &d}, {&a, &c, &d}, {&b, &c, &d}}};
  for (const auto& f : faces) best = std::min(best, (closest_on_triangle(p, *f[0], *f[1], *f[2]) - p).norm());
  return best;
}

Embedding embed_points(const Points& v, const Tets& t, const Points& points) {
  if (t.rows() == 0) throw std::invalid_argument("the tet mesh has no tets");
  const TetGrid g = build_grid(v, t);
  Embedding out;
  out.tet.assign(points.rows(), -1);
  out.bary.resize(points.rows(), 4);
  out.outside.setZero(points.rows());
  constexpr double kInsideTol = -1e-9;
  auto bary_of = [&](const Vec3& p, int32_t e) {
    return tet_barycentric(p, row(v, t(e, 0)), row(v, t(e, 1)), row(v, t(e, 2)), row(v, t(e, 3)));
  };
  for (Eigen::Index q = 0; q < points.rows(); ++q) {
    const Vec3 p = row(points, static_cast<int32_t>(q));
    const auto c = g.cell_of(p);
    // Cheap path: a tet of the point's own cell contains it.
    int32_t found = -1;
    Eigen::Vector4d lam;
    const int cell = g.index(c[0], c[1], c[2]);
    for (int32_t k = g.start[cell]; k < g.start[cell + 1] && found < 0; ++k) {
      lam = bary_of(p, g.items[k]);
      if (lam.minCoeff() >= kInsideTol) found = g.items[k];
    }
    double dist = 0.0;
    if (found < 0) {
      // Nearest tet: widen the ring of cells until no unvisited cell can hold a closer tet.
      double best = std::numeric_limits<double>::infinity();
      const double h = g.cell.minCoeff();
      const int max_ring = std::max({g.n[0], g.n[1], g.n[2]});
      for (int r = 0; r <= max_ring; ++r) {
        if (best < (r - 1) * h) break;
        for_each_ring_cell(c, r, g.n, [&](int i, int j, int k) {
          const int ci = g.index(i, j, k);
          for (int32_t m = g.start[ci]; m < g.start[ci + 1]; ++m) {
            const int32_t e = g.items[m];
            const double d = point_tet_distance(p, row(v, t(e, 0)), row(v, t(e, 1)),
                                                row(v, t(e, 2)), row(v, t(e, 3)));
            if (d < best) { best = d; found = e; }
          }
        });
      }
      lam = bary_of(p, found);
      dist = best;
    }
    out.tet[q] = found;
    out.bary.row(q) = lam.transpose();
    out.outside[q] = dist;
  }
  return out;
}

}  // namespace softdeca::geometry
