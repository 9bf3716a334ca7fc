// Closest points on a triangle mesh: an axis-aligned bounding-box tree over the triangles,
// searched branch and bound. Used to register the template to an avatar, to embed an avatar's
// vertices on the registered template and to measure the fit's residual.
//
// A long triangle's box spans much of the mesh, so every query near that box tests it: a few
// thousand slivers across a head make each query test them all. Given a piece size and the
// region the queries are asked in, the tree indexes a triangle there with a longer edge as its
// parts in squares of that size in its own plane (fanned into pieces that cover it exactly), so
// a query only tests the pieces near it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace softdeca::geometry {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct SurfacePoint {
  std::int32_t triangle = -1;  // row of the triangles; -1: none (an empty surface)
  Eigen::Vector3d bary = Eigen::Vector3d::Zero();  // weights of the triangle's corners (sum 1, >= 0)
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double squared_distance = 0;
};

// The closest point on the triangle (a, b, c) to p, with its barycentric weights; exact for
// degenerate triangles too (then the closest point of an edge or a corner).
SurfacePoint closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& c);

// Which triangles a SurfaceQuery cuts into pieces: those with an edge longer than piece_size
// whose box meets [lo, hi] (where the queries are asked; elsewhere a long triangle costs
// little). piece_size 0: none.
struct Cutting {
  double piece_size = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(-1e300), hi = Eigen::Vector3d::Constant(1e300);
};

class SurfaceQuery {
 public:
  // Keeps copies; the triangles' indices must lie inside `vertices` (checked: std::invalid_argument).
  // The triangles `cutting` chooses are indexed as pieces (what a query returns is still the
  // triangle and its weights).
  SurfaceQuery(Points vertices, Triangles triangles, const Cutting& cutting = {});

  // How many entries (whole triangles and pieces) the tree over `triangles` would hold with
  // `cutting`, counted up to `stop_at`: what a caller bounds before building.
  static std::size_t entries_needed(const Points& vertices, const Triangles& triangles, const Cutting& cutting,
                                    std::size_t stop_at);

  // The same triangles on moved vertices (as many; a rigid motion, say): the tree keeps its
  // shape and the pieces their weights, the boxes are fitted again, in linear time.
  void move(Points vertices);

  // The closest surface point to p, or triangle -1 when the surface is empty. Points farther
  // than max_distance may be skipped (then triangle -1): a bound makes queries far cheaper.
  // `visits`, when given, is increased by the tree nodes the search looked at.
  SurfacePoint closest(const Eigen::Vector3d& p, double max_distance = -1, std::size_t* visits = nullptr) const;

  const Points& vertices() const { return v_; }
  const Triangles& triangles() const { return f_; }
  std::size_t entries() const { return order_.size(); }  // whole triangles and pieces in the tree

 private:
  struct Node {
    Eigen::Vector3d lo, hi;
    std::int32_t left = -1, right = -1;  // children, or -1 for a leaf
    std::int32_t first = 0, count = 0;   // a leaf's range of order_
  };
  // Part of a long triangle: its corners, and the weights of the triangle's corners at each.
  struct Piece {
    std::int32_t triangle;
    float at[3][3];
    float weight[3][3];
  };
  void corners(std::int32_t entry, Eigen::Vector3d& a, Eigen::Vector3d& b, Eigen::Vector3d& c) const;
  // The tree over order_[first, first + count) (places of `centres`), split at the median
  // centre along the centres' widest axis; fit_boxes() then gives every node its box.
  std::int32_t build(std::int32_t first, std::int32_t count, const std::vector<Eigen::Vector3d>& centres);
  void fit_boxes();

  Points v_;
  Triangles f_;
  std::vector<Piece> pieces_;
  std::vector<Node> nodes_;
  std::vector<std::int32_t> order_;  // entries grouped by leaf: a triangle t >= 0, or piece -1 - e
};

}  // namespace softdeca::geometry
