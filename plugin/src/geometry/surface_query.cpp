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

namespace {
using Weights = Eigen::Matrix3d;  // row k: the weights of a triangle's corners at a piece's corner k

// A corner of a part of a triangle: its coordinates in the triangle's plane (u along its
// longest edge, v across) and the weights of the triangle's corners there.
struct Corner {
  double uv[2];
  Eigen::Vector3d w;
};
// A convex part of a triangle; clipping a triangle by four lines leaves at most 7 corners (the
// room beyond is for rounding, which can make a corner cross a line twice).
struct Polygon {
  static constexpr int kRoom = 16;
  Corner c[kRoom];
  int n = 0;
  void add(const Corner& corner) {
    if (n < kRoom) c[n++] = corner;
  }
};

// The part of `in` where sign * (coordinate axis - at) >= 0, in the same winding.
void clip(const Polygon& in, int axis, double at, double sign, Polygon& out) {
  out.n = 0;
  for (int k = 0; k < in.n; ++k) {
    const Corner& p = in.c[k];
    const Corner& q = in.c[(k + 1) % in.n];
    const double dp = sign * (p.uv[axis] - at), dq = sign * (q.uv[axis] - at);
    if (dp >= 0) out.add(p);
    if ((dp >= 0) != (dq >= 0)) {
      const double t = dp / (dp - dq);
      out.add({{p.uv[0] + t * (q.uv[0] - p.uv[0]), p.uv[1] + t * (q.uv[1] - p.uv[1])}, p.w + t * (q.w - p.w)});
    }
  }
}

// The triangle (a, b, c) cut by squares of side `size` in its own plane, each part fanned into
// pieces; `emit` gets each piece's corner weights (in the triangle's winding) and returns false
// to stop. A sliver gives about two pieces per `size` of its length, a large triangle about
// two per square of its area.
template <class Emit>
void cut(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double size, Emit&& emit) {
  const Eigen::Vector3d p[3] = {a, b, c};
  int first = 0;  // the longest edge runs from corner `first` to the next
  for (int k = 1; k < 3; ++k)
    if ((p[(k + 1) % 3] - p[k]).squaredNorm() > (p[(first + 1) % 3] - p[first]).squaredNorm()) first = k;
  const Eigen::Vector3d origin = p[first], along = p[(first + 1) % 3] - origin;
  const double length = along.norm();
  const Eigen::Vector3d u = along / length;
  Eigen::Vector3d v = (p[(first + 2) % 3] - origin) - (p[(first + 2) % 3] - origin).dot(u) * u;
  v = v.norm() > 0 ? Eigen::Vector3d(v.normalized()) : Eigen::Vector3d::Zero();  // a triangle without area: all on u
  Polygon whole;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d d = p[k] - origin;
    whole.add({{d.dot(u), d.dot(v)}, Eigen::Vector3d::Unit(k)});
  }
  // The other two corners project inside the longest edge: u spans [0, length].
  Polygon strip, half, cell, quarter;
  for (double s = 0; s * size < length; ++s) {
    clip(whole, 0, s * size, 1, half);
    clip(half, 0, std::min(length, (s + 1) * size), -1, strip);
    if (strip.n < 3) continue;
    double lo = strip.c[0].uv[1], hi = lo;
    for (int k = 1; k < strip.n; ++k) lo = std::min(lo, strip.c[k].uv[1]), hi = std::max(hi, strip.c[k].uv[1]);
    for (double r = 0; r == 0 || lo + r * size < hi; ++r) {
      clip(strip, 1, lo + r * size, 1, quarter);
      clip(quarter, 1, std::min(hi, lo + (r + 1) * size), -1, cell);
      for (int k = 1; k + 1 < cell.n; ++k) {
        Weights w;
        w.row(0) = cell.c[0].w.transpose();
        w.row(1) = cell.c[k].w.transpose();
        w.row(2) = cell.c[k + 1].w.transpose();
        if (!emit(w)) return;
      }
    }
  }
}

bool cut_here(const Points& v, const Triangles& f, Eigen::Index t, const Cutting& cutting) {
  if (!(cutting.piece_size > 0)) return false;
  Eigen::Vector3d lo = v.row(f(t, 0)), hi = lo;
  bool longer = false;
  for (int k = 0; k < 3; ++k) {
    lo = lo.cwiseMin(v.row(f(t, k)).transpose());
    hi = hi.cwiseMax(v.row(f(t, k)).transpose());
    longer = longer || (v.row(f(t, k)) - v.row(f(t, (k + 1) % 3))).squaredNorm() > cutting.piece_size * cutting.piece_size;
  }
  return longer && (lo.array() <= cutting.hi.array()).all() && (hi.array() >= cutting.lo.array()).all();
}

void check_indices(const Points& v, const Triangles& f) {
  if (f.size() && (f.minCoeff() < 0 || f.maxCoeff() >= v.rows()))
    throw std::invalid_argument("surface query: a triangle index is outside the vertices");
}
}  // namespace

std::size_t SurfaceQuery::entries_needed(const Points& v, const Triangles& f, const Cutting& cutting, std::size_t stop_at) {
  check_indices(v, f);
  std::size_t n = 0;
  for (Eigen::Index t = 0; t < f.rows() && n < stop_at; ++t) {
    if (!cut_here(v, f, t, cutting)) {
      ++n;
      continue;
    }
    cut(v.row(f(t, 0)), v.row(f(t, 1)), v.row(f(t, 2)), cutting.piece_size, [&](const Weights&) { return ++n < stop_at; });
  }
  return std::min(n, stop_at);
}

SurfaceQuery::SurfaceQuery(Points vertices, Triangles triangles, const Cutting& cutting)
    : v_(std::move(vertices)), f_(std::move(triangles)) {
  check_indices(v_, f_);
  constexpr auto kMaxEntries = static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() / 2);
  order_.reserve(static_cast<std::size_t>(f_.rows()));
  for (Eigen::Index t = 0; t < f_.rows(); ++t) {
    if (!cut_here(v_, f_, t, cutting)) {
      order_.push_back(static_cast<std::int32_t>(t));
    } else {
      const Eigen::Vector3d p[3] = {v_.row(f_(t, 0)), v_.row(f_(t, 1)), v_.row(f_(t, 2))};
      cut(p[0], p[1], p[2], cutting.piece_size, [&](const Weights& w) {
        Piece piece{static_cast<std::int32_t>(t), {}, {}};
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d at = w(k, 0) * p[0] + w(k, 1) * p[1] + w(k, 2) * p[2];
          for (int c = 0; c < 3; ++c) {
            piece.at[k][c] = static_cast<float>(at[c]);
            piece.weight[k][c] = static_cast<float>(w(k, c));
          }
        }
        order_.push_back(-1 - static_cast<std::int32_t>(pieces_.size()));
        pieces_.push_back(piece);
        return true;
      });
    }
    if (order_.size() > kMaxEntries) throw std::invalid_argument("surface query: too many pieces of long triangles");
  }
  // The tree is built over places in `entries`; order_ then holds the entries in the leaves' order.
  std::vector<std::int32_t> entries;
  entries.swap(order_);
  const auto n = static_cast<std::int32_t>(entries.size());
  std::vector<Eigen::Vector3d> centres(static_cast<std::size_t>(n));
  order_.resize(static_cast<std::size_t>(n));
  for (std::int32_t i = 0; i < n; ++i) {
    Eigen::Vector3d a, b, c;
    corners(entries[static_cast<std::size_t>(i)], a, b, c);
    centres[static_cast<std::size_t>(i)] = (a + b + c) / 3.0;
    order_[static_cast<std::size_t>(i)] = i;
  }
  nodes_.reserve(static_cast<std::size_t>(2 * n / kLeafSize + 2));
  if (n) build(0, n, centres);
  for (std::int32_t& e : order_) e = entries[static_cast<std::size_t>(e)];
  fit_boxes();
}

void SurfaceQuery::corners(std::int32_t entry, Eigen::Vector3d& a, Eigen::Vector3d& b, Eigen::Vector3d& c) const {
  if (entry >= 0) {
    a = v_.row(f_(entry, 0));
    b = v_.row(f_(entry, 1));
    c = v_.row(f_(entry, 2));
    return;
  }
  const Piece& piece = pieces_[static_cast<std::size_t>(-1 - entry)];
  a = Eigen::Vector3f(piece.at[0]).cast<double>();
  b = Eigen::Vector3f(piece.at[1]).cast<double>();
  c = Eigen::Vector3f(piece.at[2]).cast<double>();
}

void SurfaceQuery::move(Points vertices) {
  if (vertices.rows() != v_.rows()) throw std::invalid_argument("surface query: moved vertices of another count");
  v_ = std::move(vertices);
  for (Piece& piece : pieces_) {
    const Eigen::Vector3d p[3] = {v_.row(f_(piece.triangle, 0)), v_.row(f_(piece.triangle, 1)), v_.row(f_(piece.triangle, 2))};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d at = double(piece.weight[k][0]) * p[0] + double(piece.weight[k][1]) * p[1] + double(piece.weight[k][2]) * p[2];
      for (int c = 0; c < 3; ++c) piece.at[k][c] = static_cast<float>(at[c]);
    }
  }
  fit_boxes();
}

void SurfaceQuery::fit_boxes() {
  // Children come after their parent: from the last node back, every child is fitted first.
  for (std::size_t i = nodes_.size(); i-- > 0;) {
    Node& node = nodes_[i];
    if (node.left >= 0) {
      const Node& l = nodes_[static_cast<std::size_t>(node.left)];
      const Node& r = nodes_[static_cast<std::size_t>(node.right)];
      node.lo = l.lo.cwiseMin(r.lo);
      node.hi = l.hi.cwiseMax(r.hi);
      continue;
    }
    node.lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    node.hi = -node.lo;
    for (std::int32_t j = node.first; j < node.first + node.count; ++j) {
      Eigen::Vector3d corner[3];
      corners(order_[static_cast<std::size_t>(j)], corner[0], corner[1], corner[2]);
      for (const Eigen::Vector3d& x : corner) {
        node.lo = node.lo.cwiseMin(x);
        node.hi = node.hi.cwiseMax(x);
      }
    }
  }
}

std::int32_t SurfaceQuery::build(std::int32_t first, std::int32_t count, const std::vector<Eigen::Vector3d>& centres) {
  const auto index = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  if (count <= kLeafSize) {
    nodes_[static_cast<std::size_t>(index)].first = first;
    nodes_[static_cast<std::size_t>(index)].count = count;
    return index;
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::int32_t i = first; i < first + count; ++i) {
    const Eigen::Vector3d& c = centres[static_cast<std::size_t>(order_[static_cast<std::size_t>(i)])];
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
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

SurfacePoint SurfaceQuery::closest(const Eigen::Vector3d& p, double max_distance, std::size_t* visits) const {
  SurfacePoint best;
  best.squared_distance = max_distance >= 0 ? max_distance * max_distance : std::numeric_limits<double>::infinity();
  if (nodes_.empty()) return best;
  std::int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  std::size_t visited = 0;
  while (top) {
    const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
    ++visited;
    if (box_squared_distance(p, node.lo, node.hi) >= best.squared_distance) continue;
    if (node.left < 0) {
      for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
        const std::int32_t e = order_[static_cast<std::size_t>(i)];
        Eigen::Vector3d a, b, c;
        corners(e, a, b, c);
        SurfacePoint s = closest_on_triangle(p, a, b, c);
        if (!(s.squared_distance < best.squared_distance)) continue;
        if (e >= 0) {
          s.triangle = e;
        } else {  // the piece's weights, as the triangle's
          const Piece& piece = pieces_[static_cast<std::size_t>(-1 - e)];
          Eigen::Vector3d w = Eigen::Vector3d::Zero();
          for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j) w[j] += s.bary[k] * double(piece.weight[k][j]);
          s.triangle = piece.triangle;
          s.bary = w;
        }
        best = s;
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
  if (visits) *visits += visited;
  if (best.triangle < 0) best.squared_distance = std::numeric_limits<double>::infinity();
  return best;
}

}  // namespace softdeca::geometry
