#include "geometry/intersections.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace softdeca::geometry {
namespace {
using Vec3 = Eigen::Vector3d;

// Segment pq against closed triangle abc (Möller-Trumbore without culling). Segments lying in
// the triangle's plane are left to the coplanar test.
bool segment_hits_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                           const Vec3& c) {
  const Vec3 dir = q - p, e1 = b - a, e2 = c - a;
  const Vec3 h = dir.cross(e2);
  const double det = e1.dot(h);
  const double scale = e1.norm() * e2.norm() * dir.norm();
  if (std::abs(det) <= 1e-12 * scale) return false;
  const double inv = 1.0 / det;
  const Vec3 s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0.0 || u > 1.0) return false;
  const Vec3 qv = s.cross(e1);
  const double v = inv * dir.dot(qv);
  if (v < 0.0 || u + v > 1.0) return false;
  const double t = inv * e2.dot(qv);
  return t >= 0.0 && t <= 1.0;
}

bool coplanar_overlap(const std::array<Vec3, 3>& A, const std::array<Vec3, 3>& B) {
  const Vec3 n = (A[1] - A[0]).cross(A[2] - A[0]);
  const double nn = n.norm();
  if (nn == 0) return false;
  for (const auto& p : B)
    if (std::abs(n.dot(p - A[0])) > 1e-12 * nn * (A[1] - A[0]).norm()) return false;
  // Separating axis test in the plane: edge normals of both triangles.
  auto separated = [&](const std::array<Vec3, 3>& X, const std::array<Vec3, 3>& Y) {
    for (int k = 0; k < 3; ++k) {
      const Vec3 axis = n.cross(X[(k + 1) % 3] - X[k]);
      double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
      for (const auto& p : X) { xmin = std::min(xmin, axis.dot(p)); xmax = std::max(xmax, axis.dot(p)); }
      for (const auto& p : Y) { ymin = std::min(ymin, axis.dot(p)); ymax = std::max(ymax, axis.dot(p)); }
      if (xmax <= ymin || ymax <= xmin) return true;
    }
    return false;
  };
  return !separated(A, B) && !separated(B, A);
}

struct Box {
  Vec3 lo, hi;
};

Box tri_box(const TriPoints& v, const Triangles& f, Eigen::Index t) {
  Box b{v.row(f(t, 0)).transpose(), v.row(f(t, 0)).transpose()};
  for (int k = 1; k < 3; ++k) {
    b.lo = b.lo.cwiseMin(v.row(f(t, k)).transpose());
    b.hi = b.hi.cwiseMax(v.row(f(t, k)).transpose());
  }
  return b;
}

// Spatial hash of triangle boxes (cell size ~ 2x the mean edge), candidate pairs by shared cell.
template <class Visit>
void for_candidate_pairs(const std::vector<Box>& A, const std::vector<Box>& B, double cell, Visit visit) {
  std::unordered_map<int64_t, std::vector<int32_t>> grid;
  auto key = [](int64_t i, int64_t j, int64_t k) { return (i * 73856093) ^ (j * 19349663) ^ (k * 83492791); };
  auto range = [&](const Box& b, std::array<int64_t, 6>& r) {
    for (int c = 0; c < 3; ++c) {
      r[c] = static_cast<int64_t>(std::floor(b.lo[c] / cell));
      r[c + 3] = static_cast<int64_t>(std::floor(b.hi[c] / cell));
    }
  };
  std::array<int64_t, 6> r{};
  for (std::size_t t = 0; t < B.size(); ++t) {
    range(B[t], r);
    for (int64_t i = r[0]; i <= r[3]; ++i)
      for (int64_t j = r[1]; j <= r[4]; ++j)
        for (int64_t k = r[2]; k <= r[5]; ++k) grid[key(i, j, k)].push_back(static_cast<int32_t>(t));
  }
  std::vector<int32_t> cand;
  for (std::size_t s = 0; s < A.size(); ++s) {
    range(A[s], r);
    cand.clear();
    for (int64_t i = r[0]; i <= r[3]; ++i)
      for (int64_t j = r[1]; j <= r[4]; ++j)
        for (int64_t k = r[2]; k <= r[5]; ++k) {
          auto it = grid.find(key(i, j, k));
          if (it != grid.end()) cand.insert(cand.end(), it->second.begin(), it->second.end());
        }
    std::sort(cand.begin(), cand.end());
    cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    for (int32_t t : cand) {
      const Box &a = A[s], &b = B[t];
      if ((a.hi.array() < b.lo.array()).any() || (b.hi.array() < a.lo.array()).any()) continue;
      if (!visit(static_cast<int32_t>(s), t)) return;
    }
  }
}

double mean_edge(const TriPoints& v, const Triangles& f) {
  double s = 0;
  for (Eigen::Index t = 0; t < f.rows(); ++t) s += (v.row(f(t, 0)) - v.row(f(t, 1))).norm();
  return f.rows() ? s / static_cast<double>(f.rows()) : 1.0;
}

std::array<Vec3, 3> corners(const TriPoints& v, const Triangles& f, Eigen::Index t) {
  return {v.row(f(t, 0)).transpose(), v.row(f(t, 1)).transpose(), v.row(f(t, 2)).transpose()};
}
}  // namespace

bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2) {
  const std::array<Vec3, 3> A{a0, a1, a2}, B{b0, b1, b2};
  for (int k = 0; k < 3; ++k) {
    if (segment_hits_triangle(A[k], A[(k + 1) % 3], b0, b1, b2)) return true;
    if (segment_hits_triangle(B[k], B[(k + 1) % 3], a0, a1, a2)) return true;
  }
  return coplanar_overlap(A, B);
}

std::vector<std::pair<int32_t, int32_t>> self_intersections(const TriPoints& v, const Triangles& f,
                                                            std::size_t max_pairs) {
  std::vector<Box> boxes(f.rows());
  for (Eigen::Index t = 0; t < f.rows(); ++t) boxes[t] = tri_box(v, f, t);
  std::vector<std::pair<int32_t, int32_t>> hits;
  for_candidate_pairs(boxes, boxes, 2.0 * mean_edge(v, f), [&](int32_t i, int32_t j) {
    if (i >= j) return true;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (f(i, a) == f(j, b)) return true;  // neighbours touch by construction
    const auto A = corners(v, f, i), B = corners(v, f, j);
    if (triangles_intersect(A[0], A[1], A[2], B[0], B[1], B[2])) hits.emplace_back(i, j);
    return hits.size() < max_pairs;
  });
  return hits;
}

std::vector<std::pair<int32_t, int32_t>> mesh_intersections(const TriPoints& va, const Triangles& fa,
                                                            const TriPoints& vb, const Triangles& fb,
                                                            std::size_t max_pairs) {
  std::vector<Box> A(fa.rows()), B(fb.rows());
  for (Eigen::Index t = 0; t < fa.rows(); ++t) A[t] = tri_box(va, fa, t);
  for (Eigen::Index t = 0; t < fb.rows(); ++t) B[t] = tri_box(vb, fb, t);
  std::vector<std::pair<int32_t, int32_t>> hits;
  const double cell = 2.0 * std::max(mean_edge(va, fa), mean_edge(vb, fb));
  for_candidate_pairs(A, B, cell, [&](int32_t i, int32_t j) {
    const auto P = corners(va, fa, i), Q = corners(vb, fb, j);
    if (triangles_intersect(P[0], P[1], P[2], Q[0], Q[1], Q[2])) hits.emplace_back(i, j);
    return hits.size() < max_pairs;
  });
  return hits;
}

}  // namespace softdeca::geometry
