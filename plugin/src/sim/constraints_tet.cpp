#include "sim/constraints_tet.h"

#include <Eigen/Dense>
#include <cmath>

namespace softdeca::sim {

TetGroup::TetGroup(const char* name, std::vector<TetElement> elements, StrainLimit mode, double pascal_per_unit)
    : ElementGroup(name, std::move(elements)), mode_(mode), pa_(pascal_per_unit) {}

std::vector<TetElement> TetGroup::make_elements(const Positions& rest, const TetIndices& tets, bool reorient) {
  std::vector<TetElement> out(static_cast<std::size_t>(tets.rows()));
  for (Eigen::Index i = 0; i < tets.rows(); ++i) {
    TetElement& e = out[static_cast<std::size_t>(i)];
    for (int k = 0; k < 4; ++k) e.v[static_cast<std::size_t>(k)] = tets(i, k);
    auto edges = [&] {
      Eigen::Matrix3d D;
      for (int k = 0; k < 3; ++k) D.col(k) = (rest.row(e.v[k + 1]) - rest.row(e.v[0])).transpose();
      return D;
    };
    Eigen::Matrix3d D = edges();
    if (D.determinant() < 0 && reorient) {
      std::swap(e.v[2], e.v[3]);
      D = edges();
    }
    e.volume = std::abs(D.determinant()) / 6.0;
    e.Dm_inv = D.inverse();
    e.w_volume = e.w_strain = 0;
    e.target_det = 1;
    e.max_strain = -INFINITY;
  }
  return out;
}

void TetGroup::jacobian(Triplets& out, Eigen::Index row_offset) const {
  // Row r of a tet is column r of F = sum_j (x_{j+1} - x_0) Dm_inv(j, r).
  for (std::size_t i = 0; i < el_.size(); ++i) {
    const TetElement& e = el_[i];
    for (int r = 0; r < 3; ++r) {
      const Eigen::Index row = row_offset + 3 * static_cast<Eigen::Index>(i) + r;
      double sum = 0;
      for (int j = 0; j < 3; ++j) {
        out.emplace_back(row, e.v[static_cast<std::size_t>(j + 1)], e.Dm_inv(j, r));
        sum += e.Dm_inv(j, r);
      }
      out.emplace_back(row, e.v[0], -sum);
    }
  }
}

void TetGroup::weights(Eigen::Ref<Eigen::VectorXd> w) const {
  // Energy w_k * Pa * V * |F - P_k|^2 = 1/2 W |F - P_k|^2 with W = 2 Pa V w_k.
  for (std::size_t i = 0; i < el_.size(); ++i)
    w.segment<3>(3 * static_cast<Eigen::Index>(i))
        .setConstant(2 * pa_ * el_[i].volume * (el_[i].w_volume + el_[i].w_strain));
}

double TetGroup::project(const Positions& x, Eigen::Index begin, Eigen::Index end, RowBlock P) const {
  double energy = 0;
  for (Eigen::Index i = begin; i < end; ++i) {
    const TetElement& e = el_[static_cast<std::size_t>(i)];
    Eigen::Matrix3d Ds;
    for (int k = 0; k < 3; ++k) Ds.col(k) = (x.row(e.v[k + 1]) - x.row(e.v[0])).transpose();
    const Eigen::Matrix3d F = Ds * e.Dm_inv;
    const Svd3 svd = svd3(F);
    Eigen::Matrix3d target = Eigen::Matrix3d::Zero();
    double elem = 0;
    if (e.w_volume > 0) {
      const Eigen::Matrix3d Pv = project_volume(svd, e.target_det);
      target += e.w_volume * Pv;
      elem += e.w_volume * (F - Pv).squaredNorm();
    }
    if (e.w_strain > 0) {
      const Eigen::Matrix3d Ps = std::isinf(e.max_strain) ? project_rotation(svd)
                                                          : project_strain_limit(F, svd, e.max_strain, mode_);
      target += e.w_strain * Ps;
      elem += e.w_strain * (F - Ps).squaredNorm();
    }
    const double wsum = e.w_volume + e.w_strain;
    if (wsum > 0) target /= wsum;
    P.middleRows<3>(3 * i) = target.transpose();  // row r = column r of the target F
    energy += pa_ * e.volume * elem;
  }
  return energy;
}

}  // namespace softdeca::sim
