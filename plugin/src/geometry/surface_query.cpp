#include "geometry/surface_query.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace softdeca::geometry {

namespace {
constexpr std::int32_t kLeafSize = 4;

double box_squared_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double d = 0;
  for (int i = 0; i < 3; ++i) {
    const double e = p[i] < lo[i] ? lo[i] - p[i] : p[i] > hi[i] ? p[i] - hi[i] : 0;
    d += e * e;
  }
  return d;
}
}  // namespace

SurfacePoint closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& c) {
  // Ericson, Real-Time Collision Detection, 5.1.5: the Voronoi regions of corners, edges, face.
  SurfacePoint r;
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const auto at = [&](double u, double v, double w) {
    r.bary = {u, v, w};
    r.point = u * a + v * b + w * c;
    r.squared_distance = (p - r.point).squaredNorm();
    return r;
  };
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return at(1, 0, 0);
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return at(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 - d3 > 0 ? d1 / (d1 - d3) : 0;
    return at(1 - v, v, 0);
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return at(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 - d6 > 0 ? d2 / (d2 - d6) : 0;
    return at(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double den = (d4 - d3) + (d5 - d6);
    const double w = den > 0 ? (d4 - d3) / den : 0;
    return at(0, 1 - w, w);
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) return at(1, 0, 0);  // a degenerate triangle whose regions all failed: a corner
  const double v = vb / sum, w = vc / sum;
  return at(1 - v - w, v, w);
}

SurfaceQuery::SurfaceQuery(Points vertices, Triangles triangles) : v_(std::move(vertices)), f_(std::move(triangles)) {
  if (f_.size() && (f_.minCoeff() < 0 || f_.maxCoeff() >= v_.rows()))
    throw std::invalid_argument("surface query: a triangle index is outside the vertices");
  const auto n = static_cast<std::int32_t>(f_.rows());
  order_.resize(static_cast<std::size_t>(n));
  std::vector<Eigen::Vector3d> centres(static_cast<std::size_t>(n));
  for (std::int32_t t = 0; t < n; ++t) {
    order_[static_cast<std::size_t>(t)] = t;
    centres[static_cast<std::size_t>(t)] = (v_.row(f_(t, 0)) + v_.row(f_(t, 1)) + v_.row(f_(t, 2))).transpose() / 3.0;
  }
  nodes_.reserve(static_cast<std::size_t>(2 * n / kLeafSize + 2));
  if (n) build(0, n, centres);
}

std::int32_t SurfaceQuery::build(std::int32_t first, std::int32_t count, std::vector<Eigen::Vector3d>& centres) {
  const auto index = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Eigen::Vector3d clo = lo, chi = hi;
  for (std::int32_t i = first; i < first + count; ++i) {
    const std::int32_t t = order_[static_cast<std::size_t>(i)];
    for (int k = 0; k < 3; ++k) {
      lo = lo.cwiseMin(v_.row(f_(t, k)).transpose());
      hi = hi.cwiseMax(v_.row(f_(t, k)).transpose());
    }
    clo = clo.cwiseMin(centres[static_cast<std::size_t>(t)]);
    chi = chi.cwiseMax(centres[static_cast<std::size_t>(t)]);
  }
  nodes_[static_cast<std::size_t>(index)].lo = lo;
  nodes_[static_cast<std::size_t>(index)].hi = hi;
  if (count <= kLeafSize) {
    nodes_[static_cast<std::size_t>(index)].first = first;
    nodes_[static_cast<std::size_t>(index)].count = count;
    return index;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const std::int32_t half = count / 2;
  auto begin = order_.begin() + first;
  std::nth_element(begin, begin + half, begin + count, [&](std::int32_t a, std::int32_t b) {
    return centres[static_cast<std::size_t>(a)][axis] < centres[static_cast<std::size_t>(b)][axis];
  });
  const std::int32_t left = build(first, half, centres);
  const std::int32_t right = build(first + half, count - half, centres);
  nodes_[static_cast<std::size_t>(index)].left = left;
  nodes_[static_cast<std::size_t>(index)].right = right;
  return index;
}

SurfacePoint SurfaceQuery::closest(const Eigen::Vector3d& p, double max_distance) const {
  SurfacePoint best;
  best.squared_distance = max_distance >= 0 ? max_distance * max_distance : std::numeric_limits<double>::infinity();
  if (nodes_.empty()) return best;
  std::int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top) {
    const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
    if (box_squared_distance(p, node.lo, node.hi) >= best.squared_distance) continue;
    if (node.left < 0) {
      for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
        const std::int32_t t = order_[static_cast<std::size_t>(i)];
        SurfacePoint s = closest_on_triangle(p, v_.row(f_(t, 0)), v_.row(f_(t, 1)), v_.row(f_(t, 2)));
        if (s.squared_distance < best.squared_distance) {
          s.triangle = t;
          best = s;
        }
      }
      continue;
    }
    // The nearer child last, so it is searched first.
    const Node& l = nodes_[static_cast<std::size_t>(node.left)];
    const Node& r = nodes_[static_cast<std::size_t>(node.right)];
    const bool left_first = box_squared_distance(p, l.lo, l.hi) <= box_squared_distance(p, r.lo, r.hi);
    stack[top++] = left_first ? node.right : node.left;
    stack[top++] = left_first ? node.left : node.right;
  }
  if (best.triangle < 0) best.squared_distance = std::numeric_limits<double>::infinity();
  return best;
}

}  // namespace softdeca::geometry
