#include "sim/constraints_surface.h"

#include <Eigen/Dense>
#include <cmath>

#include "core/error.h"
#include "geometry/cotan.h"
#include "sim/svd3.h"

namespace softdeca::sim {

TriangleStrainGroup::TriangleStrainGroup(const char* name, std::vector<TriangleElement> elements,
                                         double pascal_per_unit)
    : ElementGroup(name, std::move(elements)), pa_(pascal_per_unit) {}

void TriangleStrainGroup::set_rest(TriangleElement& e, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d n = e1.cross(e2);
  e.area = 0.5 * n.norm();
  require(e.area > 1e-14 * (e1.squaredNorm() + e2.squaredNorm()) && e.area > 0,
          "a strain triangle is degenerate in the rest shape");
  const Eigen::Vector3d t1 = e1.normalized(), t2 = n.normalized().cross(t1);
  Eigen::Matrix2d Dm;
  Dm << e1.norm(), e2.dot(t1), 0, e2.dot(t2);
  e.Dm_inv = Dm.inverse();
}

void TriangleStrainGroup::jacobian(Triplets& out, Eigen::Index row_offset) const {
  for (std::size_t i = 0; i < el_.size(); ++i) {
    const TriangleElement& e = el_[i];
    for (int r = 0; r < 2; ++r) {
      const Eigen::Index row = row_offset + 2 * static_cast<Eigen::Index>(i) + r;
      const double coeff[3] = {-(e.Dm_inv(0, r) + e.Dm_inv(1, r)), e.Dm_inv(0, r), e.Dm_inv(1, r)};
      for (std::size_t j = 0; j < 3; ++j)
        for (std::size_t k = 0; k < e.corner[j].vertex.size(); ++k)
          out.emplace_back(row, e.corner[j].vertex[k], coeff[j] * e.corner[j].weight[k]);
    }
  }
}

void TriangleStrainGroup::weights(Eigen::Ref<Eigen::VectorXd> w) const {
  for (std::size_t i = 0; i < el_.size(); ++i)
    w.segment<2>(2 * static_cast<Eigen::Index>(i)).setConstant(2 * pa_ * el_[i].area * el_[i].weight);
}

double TriangleStrainGroup::project(const Positions& x, Eigen::Index begin, Eigen::Index end, RowBlock P) const {
  double energy = 0;
  for (Eigen::Index i = begin; i < end; ++i) {
    const TriangleElement& e = el_[static_cast<std::size_t>(i)];
    const Eigen::RowVector3d c0 = e.corner[0].apply(x);
    Eigen::Matrix<double, 3, 2> Ds;
    Ds.col(0) = (e.corner[1].apply(x) - c0).transpose();
    Ds.col(1) = (e.corner[2].apply(x) - c0).transpose();
    const Eigen::Matrix<double, 3, 2> F = Ds * e.Dm_inv;
    const Polar32 polar = polar32(F);
    P.middleRows<2>(2 * i) = polar.R.transpose();
    energy += pa_ * e.area * e.weight * (F - polar.R).squaredNorm();
  }
  return energy;
}

BendingGroup::BendingGroup(std::vector<BendingElement> elements, double pascal_per_unit)
    : ElementGroup("skull bending", std::move(elements)), pa_(pascal_per_unit) {}

void BendingGroup::jacobian(Triplets& out, Eigen::Index row_offset) const {
  for (std::size_t i = 0; i < el_.size(); ++i)
    for (std::size_t k = 0; k < el_[i].laplacian.vertex.size(); ++k)
      out.emplace_back(row_offset + static_cast<Eigen::Index>(i), el_[i].laplacian.vertex[k],
                       el_[i].laplacian.weight[k]);
}

void BendingGroup::weights(Eigen::Ref<Eigen::VectorXd> w) const {
  for (std::size_t i = 0; i < el_.size(); ++i) w[static_cast<Eigen::Index>(i)] = 2 * pa_ * el_[i].weight;
}

double BendingGroup::project(const Positions& x, Eigen::Index begin, Eigen::Index end, RowBlock P) const {
  double energy = 0;
  for (Eigen::Index i = begin; i < end; ++i) {
    const BendingElement& e = el_[static_cast<std::size_t>(i)];
    const Eigen::Vector3d lap = e.laplacian.apply(x).transpose();
    // min over rotations R of |lap - R rest|: rest's length along lap's direction.
    const double rest_len = e.rest.norm(), len = lap.norm();
    Eigen::Vector3d target = e.rest;
    if (rest_len == 0) target.setZero();
    else if (len > 1e-12 * rest_len) target = lap * (rest_len / len);
    P.row(i) = target.transpose();
    energy += pa_ * e.weight * (lap - target).squaredNorm();
  }
  return energy;
}

std::vector<BendingElement> make_bending_elements(const Positions& rest, const TriIndices& triangles,
                                                  double thickness, const Eigen::VectorXd& weight_per_vertex) {
  std::vector<BendingElement> out;
  if (triangles.rows() == 0) return out;
  const Eigen::SparseMatrix<double> L = geometry::cotan_laplacian(rest, triangles);
  const Eigen::VectorXd area = geometry::voronoi_areas(rest, triangles);
  const double h3 = thickness * thickness * thickness;
  for (Eigen::Index v = 0; v < L.outerSize(); ++v) {
    if (!(area[v] > 0)) continue;  // not a skull vertex
    BendingElement e;
    Eigen::Vector3d lap = Eigen::Vector3d::Zero();
    for (Eigen::SparseMatrix<double>::InnerIterator it(L, v); it; ++it) {
      // L is symmetric: column v holds row v.
      e.laplacian.vertex.push_back(static_cast<int32_t>(it.row()));
      e.laplacian.weight.push_back(it.value() / area[v]);
      lap += it.value() / area[v] * rest.row(it.row()).transpose();
    }
    e.rest = lap;
    e.weight = weight_per_vertex[v] * area[v] * h3;
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace softdeca::sim
