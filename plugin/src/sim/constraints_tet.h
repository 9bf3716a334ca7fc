// Tet constraints: volume (det F toward a target, eq. B.1) and strain (F toward its rotation,
// eq. B.2, optionally limited to sigma_max > eps as in eq. 10) on one tet group: the soft
// tissue, the muscle tissue, or the connecting tets. Both share the tet's G (F = Ds Dm^-1),
// so one SVD per tet serves both and they enter the system as one weighted row triple.
#pragma once

#include <array>

#include "sim/constraints.h"
#include "sim/projections.h"

namespace softdeca::sim {

struct TetElement {
  std::array<int32_t, 4> v;
  Eigen::Matrix3d Dm_inv;  // inverse rest edge matrix [x1-x0, x2-x0, x3-x0]
  double volume;           // rest volume (m^3)
  double w_volume;         // kPa
  double w_strain;         // kPa
  double target_det;
  double max_strain;       // eps; -inf: strain always on (rotation)
};

class TetGroup final : public ElementGroup<TetElement, 3> {
 public:
  TetGroup(const char* name, std::vector<TetElement> elements, StrainLimit mode,
           double pascal_per_unit);
  void jacobian(Triplets& out, Eigen::Index row_offset) const override;
  void weights(Eigen::Ref<Eigen::VectorXd> w) const override;
  double project(const Positions& x, Eigen::Index begin, Eigen::Index end, RowBlock P) const override;

  // Builds elements from rest positions; negative tets are reoriented (swap of two vertices)
  // when `reorient`, else they are an error (validate() already refused them).
  static std::vector<TetElement> make_elements(const Positions& rest, const TetIndices& tets, bool reorient);

 private:
  StrainLimit mode_;
  double pa_;
};

}  // namespace softdeca::sim
