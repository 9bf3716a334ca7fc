// Surface constraints: triangle strain (skin triangles of S, eq. 11; skull triangles, eq. 13)
// and the skull's bending, the Laplacian with rotation (eq. 13, Appendix B: A_x |Δx - R Δb_x|^2
// with cotangent weights and Voronoi areas).
#pragma once

#include <array>

#include "sim/constraints.h"

namespace softdeca::sim {

// A triangle whose corners are embedded points (S) or plain vertices (skull).
struct TriangleElement {
  std::array<PointRow, 3> corner;
  Eigen::Matrix2d Dm_inv;  // inverse rest edges in the triangle's own 2D frame
  double area;             // rest area (m^2)
  double weight;           // kPa * thickness (m): energy weight * Pa * area * |F - R|^2
};

class TriangleStrainGroup final : public ElementGroup<TriangleElement, 2> {
 public:
  TriangleStrainGroup(const char* name, std::vector<TriangleElement> elements, double pascal_per_unit);
  void jacobian(Triplets& out, Eigen::Index row_offset) const override;
  void weights(Eigen::Ref<Eigen::VectorXd> w) const override;
  double project(const Positions& x, Eigen::Index begin, Eigen::Index end, RowBlock P) const override;

  // Rest frame of a triangle from its corners' rest positions; throws on degenerate ones.
  static void set_rest(TriangleElement& e, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c);

 private:
  double pa_;
};

struct BendingElement {
  PointRow laplacian;     // (L x)_i / A_i: the vertex's mean-curvature normal
  Eigen::Vector3d rest;   // Δb_i on the (scaled) rest skull
  double weight;          // kPa * A_i * h^3
};

class BendingGroup final : public ElementGroup<BendingElement, 1> {
 public:
  BendingGroup(std::vector<BendingElement> elements, double pascal_per_unit);
  void jacobian(Triplets& out, Eigen::Index row_offset) const override;
  void weights(Eigen::Ref<Eigen::VectorXd> w) const override;
  double project(const Positions& x, Eigen::Index begin, Eigen::Index end, RowBlock P) const override;

 private:
  double pa_;
};

// One element per vertex of `triangles`, on the given rest positions (the scaled skull);
// weight_per_vertex (kPa) is indexed by simulated vertex.
std::vector<BendingElement> make_bending_elements(const Positions& rest, const TriIndices& triangles,
                                                  double thickness, const Eigen::VectorXd& weight_per_vertex);

}  // namespace softdeca::sim
