// Closest points on a triangle mesh: an axis-aligned bounding-box tree over the triangles,
// searched branch and bound. Used to register the template to an avatar, to embed an avatar's
// vertices on the registered template and to measure the fit's residual.
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

class SurfaceQuery {
 public:
  // Keeps copies; the triangles' indices must lie inside `vertices` (checked: std::invalid_argument).
  SurfaceQuery(Points vertices, Triangles triangles);

  // The closest surface point to p, or triangle -1 when the surface is empty. Points farther
  // than max_distance may be skipped (then triangle -1): a bound makes queries far cheaper.
  SurfacePoint closest(const Eigen::Vector3d& p, double max_distance = -1) const;

  const Points& vertices() const { return v_; }
  const Triangles& triangles() const { return f_; }

 private:
  struct Node {
    Eigen::Vector3d lo, hi;
    std::int32_t left = -1, right = -1;  // children, or -1 for a leaf
    std::int32_t first = 0, count = 0;   // a leaf's range of order_
  };
  std::int32_t build(std::int32_t first, std::int32_t count, std::vector<Eigen::Vector3d>& centres);

  Points v_;
  Triangles f_;
  std::vector<Node> nodes_;
  std::vector<std::int32_t> order_;  // triangles, grouped by leaf
};

}  // namespace softdeca::geometry
