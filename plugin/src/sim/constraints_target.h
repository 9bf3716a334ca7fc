// Soft Dirichlet targets (eq. 14, B.4; landmarks eq. 22) and collision contacts (paper 3.3.2):
// a point, a fixed combination of simulated vertices, pulled to a position given per frame.
// For a contact the "point" is the difference of the two touching points and its target 0,
// which makes them coincide (Komaritzan and Botsch, projective skinning: no gap remains).
#pragma once

#include "sim/constraints.h"

namespace softdeca::sim {

struct TargetElement {
  PointRow point;
  double weight;  // W / 2 (J/m^2): energy weight * |point(x) - target|^2
};

class TargetGroup final : public ElementGroup<TargetElement, 1> {
 public:
  TargetGroup(const char* name, std::vector<TargetElement> elements);
  bool constant_projection() const override { return true; }
  void jacobian(Triplets& out, Eigen::Index row_offset) const override;
  void weights(Eigen::Ref<Eigen::VectorXd> w) const override;
  // Reads the targets from P (filled by the frame) and returns the energy.
  double project(const Positions& x, Eigen::Index begin, Eigen::Index end, RowBlock P) const override;
  const TargetElement& element(Eigen::Index i) const { return el_[static_cast<std::size_t>(i)]; }
};

}  // namespace softdeca::sim
