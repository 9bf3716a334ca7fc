#include "sim/constraints_target.h"

namespace softdeca::sim {

TargetGroup::TargetGroup(const char* name, std::vector<TargetElement> elements)
    : ElementGroup(name, std::move(elements)) {}

void TargetGroup::jacobian(Triplets& out, Eigen::Index row_offset) const {
  for (std::size_t i = 0; i < el_.size(); ++i)
    for (std::size_t k = 0; k < el_[i].point.vertex.size(); ++k)
      out.emplace_back(row_offset + static_cast<Eigen::Index>(i), el_[i].point.vertex[k], el_[i].point.weight[k]);
}

void TargetGroup::weights(Eigen::Ref<Eigen::VectorXd> w) const {
  for (std::size_t i = 0; i < el_.size(); ++i) w[static_cast<Eigen::Index>(i)] = 2 * el_[i].weight;
}

double TargetGroup::project(const Positions& x, Eigen::Index begin, Eigen::Index end, RowBlock P) const {
  double energy = 0;
  for (Eigen::Index i = begin; i < end; ++i) {
    const TargetElement& e = el_[static_cast<std::size_t>(i)];
    energy += e.weight * (e.point.apply(x) - P.row(i)).squaredNorm();
  }
  return energy;
}

}  // namespace softdeca::sim
