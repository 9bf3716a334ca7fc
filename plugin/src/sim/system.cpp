#include "sim/system.h"

#include <chrono>
#include <string>

#include "core/error.h"
#include "geometry/ldlt_factor.h"

namespace softdeca::sim {

System::~System() = default;

System::System(const Model& model, const ConstraintGroup* extra) {
  const auto t0 = std::chrono::steady_clock::now();
  const Eigen::Index n = static_cast<Eigen::Index>(model.pinned.size());
  free_index_.assign(static_cast<std::size_t>(n), -1);
  std::vector<int32_t> pin_index(static_cast<std::size_t>(n), -1);
  for (Eigen::Index v = 0; v < n; ++v) {
    if (model.pinned[static_cast<std::size_t>(v)]) {
      pin_index[static_cast<std::size_t>(v)] = static_cast<int32_t>(pinned_.size());
      pinned_.push_back(static_cast<int32_t>(v));
    } else {
      free_index_[static_cast<std::size_t>(v)] = static_cast<int32_t>(free_.size());
      free_.push_back(static_cast<int32_t>(v));
    }
  }
  require(!free_.empty(), "every vertex is pinned: nothing to simulate");

  variable_rows_ = model.variable_rows;
  rows_ = model.rows + (extra ? extra->rows() : 0);
  Triplets all;
  Eigen::VectorXd W(rows_);
  for (std::size_t g = 0; g < model.groups.size(); ++g) {
    model.groups[g]->jacobian(all, model.row_offset[g]);
    model.groups[g]->weights(W.segment(model.row_offset[g], model.groups[g]->rows()));
  }
  if (extra) {
    extra->jacobian(all, model.rows);
    extra->weights(W.segment(model.rows, extra->rows()));
  }
  Triplets free_t, var_t, pin_t;
  free_t.reserve(all.size());
  for (const auto& t : all) {
    const auto v = static_cast<std::size_t>(t.col());
    if (free_index_[v] >= 0) {
      free_t.emplace_back(t.row(), free_index_[v], t.value());
      if (t.row() < variable_rows_) var_t.emplace_back(t.row(), free_index_[v], t.value());
    } else {
      pin_t.emplace_back(t.row(), pin_index[v], t.value());
    }
  }
  all.clear();
  all.shrink_to_fit();
  const Eigen::Index nf = free_count();
  Eigen::SparseMatrix<double> G(rows_, nf), Gv(variable_rows_, nf);
  G.setFromTriplets(free_t.begin(), free_t.end());
  Gv.setFromTriplets(var_t.begin(), var_t.end());
  G_pin_.resize(rows_, static_cast<Eigen::Index>(pinned_.size()));
  G_pin_.setFromTriplets(pin_t.begin(), pin_t.end());

  J_ = RowMajorSparse(G.transpose() * W.asDiagonal());
  J_var_ = RowMajorSparse(Gv.transpose() * W.head(variable_rows_).asDiagonal());
  Eigen::SparseMatrix<double> A = (Eigen::SparseMatrix<double>(J_) * G).pruned();
  const double mean_diag = A.diagonal().sum() / static_cast<double>(nf);
  require(mean_diag > 0, "the system matrix has no stiffness on the free vertices");
  mu_ = 1e-10 * mean_diag;
  for (Eigen::Index i = 0; i < nf; ++i) A.coeffRef(i, i) += mu_;
  factor_ = std::make_unique<geometry::LdltFactor>(A);
  if (!factor_->ok() || !(factor_->diagonal().array() > 0).all())
    throw Error(SOFTDECA_ERROR_INTERNAL, "the projective dynamics matrix could not be factorised (not positive definite)");
  factor_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Positions System::frame_rhs(const Positions& P, const Positions& x, const Positions& force) const {
  Positions xp(static_cast<Eigen::Index>(pinned_.size()), 3);
  for (std::size_t i = 0; i < pinned_.size(); ++i) xp.row(static_cast<Eigen::Index>(i)) = x.row(pinned_[i]);
  Positions Y = -(G_pin_ * xp);
  Y.bottomRows(rows_ - variable_rows_) += P.bottomRows(rows_ - variable_rows_);
  Positions b = J_ * Y;
  for (std::size_t i = 0; i < free_.size(); ++i) b.row(static_cast<Eigen::Index>(i)) += force.row(free_[i]);
  return b;
}

void System::iteration_rhs(const Positions& P, const Positions& frame, const Positions& x_free, Positions& out,
                           ThreadPool* pool) const {
  out.resize(free_count(), 3);
  auto rows = [&](std::size_t begin, std::size_t end, int) {
    const int* outer = J_var_.outerIndexPtr();
    const int* inner = J_var_.innerIndexPtr();
    const double* val = J_var_.valuePtr();
    for (std::size_t i = begin; i < end; ++i) {
      Eigen::RowVector3d acc = frame.row(static_cast<Eigen::Index>(i)) + mu_ * x_free.row(static_cast<Eigen::Index>(i));
      for (int k = outer[i]; k < outer[i + 1]; ++k) acc += val[k] * P.row(inner[k]);
      out.row(static_cast<Eigen::Index>(i)) = acc;
    }
  };
  if (pool) pool->parallel_for(static_cast<std::size_t>(free_count()), rows);
  else rows(0, static_cast<std::size_t>(free_count()), 0);
}

void System::solve(const Positions& B, Positions& X) const {
  // LDL^T with fill-reducing permutation P: A = P^-1 L D L^T P (Eigen's SimplicialLDLT layout:
  // L strictly lower, column-major, unit diagonal implied).
  const geometry::LdltFactor& ldlt = *factor_;
  Positions y = ldlt.permutation() * B;
  const auto& L = ldlt.lower();
  const int* outer = L.outerIndexPtr();
  const int* inner = L.innerIndexPtr();
  const double* val = L.valuePtr();
  const Eigen::Index n = L.cols();
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::RowVector3d yj = y.row(j);
    for (int k = outer[j]; k < outer[j + 1]; ++k) y.row(inner[k]) -= val[k] * yj;
  }
  const Eigen::VectorXd& D = ldlt.diagonal();
  for (Eigen::Index j = 0; j < n; ++j) y.row(j) /= D[j];
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    Eigen::RowVector3d yj = y.row(j);
    for (int k = outer[j]; k < outer[j + 1]; ++k) yj -= val[k] * y.row(inner[k]);
    y.row(j) = yj;
  }
  X = ldlt.inverse_permutation() * y;
}

}  // namespace softdeca::sim
