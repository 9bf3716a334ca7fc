// Projective dynamics constraints (Bouaziz et al. 2014): every energy of phi† (eq. 15, 23) is
// a sum of terms 1/2 W |G x - P|^2 where G is a fixed linear map of the vertex positions
// (a deformation gradient, a Laplacian, an embedded point) and P the projection of G x onto
// the constraint's set (local step). A group owns a block of consecutive rows of the stacked
// system; each row is one 3-vector (one column of F, one Laplacian, one point).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <utility>
#include <vector>

#include "sim/mesh.h"

namespace softdeca::sim {

using Triplets = std::vector<Eigen::Triplet<double>>;
using RowBlock = Eigen::Ref<Positions>;

class ConstraintGroup {
 public:
  virtual ~ConstraintGroup() = default;
  virtual const char* name() const = 0;
  virtual Eigen::Index rows() const = 0;
  virtual Eigen::Index elements() const = 0;
  // True when P does not depend on x (targets): P is filled once per frame by the caller.
  virtual bool constant_projection() const { return false; }
  // Unweighted entries of G, rows counted from `row_offset`.
  virtual void jacobian(Triplets& out, Eigen::Index row_offset) const = 0;
  // W per row (rows() entries).
  virtual void weights(Eigen::Ref<Eigen::VectorXd> w) const = 0;
  // Local step for elements [begin, end): writes their rows of P (this group's block) unless
  // the projection is constant, and returns their energy at x.
  virtual double project(const Positions& x, Eigen::Index begin, Eigen::Index end,
                         RowBlock P) const = 0;
};

// A group of like elements, `kRowsPerElement` rows each: the name and element bookkeeping
// every group shares.
template <class Element, int kRowsPerElement>
class ElementGroup : public ConstraintGroup {
 public:
  const char* name() const override { return name_; }
  Eigen::Index rows() const override { return kRowsPerElement * elements(); }
  Eigen::Index elements() const override { return static_cast<Eigen::Index>(el_.size()); }

 protected:
  ElementGroup(const char* name, std::vector<Element> elements) : name_(name), el_(std::move(elements)) {}
  const char* name_;
  std::vector<Element> el_;
};

// A linear combination of simulated vertices (an embedded point or a difference of them).
struct PointRow {
  std::vector<int32_t> vertex;
  std::vector<double> weight;
  Eigen::RowVector3d apply(const Positions& x) const {
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (std::size_t k = 0; k < vertex.size(); ++k) p += weight[k] * x.row(vertex[k]);
    return p;
  }
};

// Positions of a list of point rows.
inline Positions embed_rows(const std::vector<PointRow>& rows, const Positions& x) {
  Positions out(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t i = 0; i < rows.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = rows[i].apply(x);
  return out;
}

}  // namespace softdeca::sim
