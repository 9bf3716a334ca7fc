#include "runtime/sparse_ldlt.h"

#include <Eigen/SparseCholesky>

#include <cmath>
#include <string>

#include "api/error.h"

namespace softdeca::runtime {

SparseLdlt::SparseLdlt(const Eigen::SparseMatrix<double>& K) : n_(static_cast<std::size_t>(K.rows())) {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt(K);
  require(ldlt.info() == Eigen::Success, "the deformation-transfer matrix cannot be factorised");
  const Eigen::VectorXd d = ldlt.vectorD();
  inv_d_.resize(n_);
  for (std::size_t i = 0; i < n_; ++i) {
    const double v = d[static_cast<Eigen::Index>(i)];
    require(v > 0 && std::isfinite(v), "the deformation-transfer matrix is not positive definite (pivot " +
                                           std::to_string(i) + ")");
    inv_d_[i] = 1.0 / v;
  }
  // Eigen: P b puts b[i] at P.indices()[i].
  const auto& p = ldlt.permutationP().indices();
  gather_.resize(n_);
  scatter_.resize(n_);
  for (std::size_t i = 0; i < n_; ++i) {
    gather_[static_cast<std::size_t>(p[static_cast<Eigen::Index>(i)])] = static_cast<std::int32_t>(i);
    scatter_[i] = p[static_cast<Eigen::Index>(i)];
  }
  // Strict lower triangle of the unit-diagonal factor.
  Eigen::SparseMatrix<double> L = ldlt.matrixL();
  L.prune([](Eigen::Index r, Eigen::Index c, double) { return r > c; });
  L.makeCompressed();
  col_ptr_.assign(L.outerIndexPtr(), L.outerIndexPtr() + L.outerSize() + 1);
  col_rows_.assign(L.innerIndexPtr(), L.innerIndexPtr() + L.nonZeros());
  upper_values_.assign(L.valuePtr(), L.valuePtr() + L.nonZeros());
  Eigen::SparseMatrix<double, Eigen::RowMajor> R = L;
  R.makeCompressed();
  row_ptr_.assign(R.outerIndexPtr(), R.outerIndexPtr() + R.outerSize() + 1);
  row_cols_.assign(R.innerIndexPtr(), R.innerIndexPtr() + R.nonZeros());
  lower_values_.assign(R.valuePtr(), R.valuePtr() + R.nonZeros());
}

std::size_t SparseLdlt::bytes() const {
  return (gather_.size() + scatter_.size() + row_ptr_.size() + row_cols_.size() + col_ptr_.size() + col_rows_.size()) * 4 +
         (inv_d_.size() + lower_values_.size() + upper_values_.size()) * 8;
}

void SparseLdlt::solve(const float* b0, const float* b1, double* y, float* x) const {
  const std::size_t n = n_;
  for (std::size_t q = 0; q < n; ++q) {
    const std::size_t s = static_cast<std::size_t>(gather_[q]) * 3;
    y[3 * q] = b0[s];
    y[3 * q + 1] = b0[s + 1];
    y[3 * q + 2] = b0[s + 2];
    if (b1) {
      y[3 * q] += b1[s];
      y[3 * q + 1] += b1[s + 1];
      y[3 * q + 2] += b1[s + 2];
    }
  }
  // Forward: L y = Pb, row by row.
  for (std::size_t i = 0; i < n; ++i) {
    double a0 = 0, a1 = 0, a2 = 0;
    for (std::int32_t p = row_ptr_[i]; p < row_ptr_[i + 1]; ++p) {
      const double l = lower_values_[static_cast<std::size_t>(p)];
      const double* yj = y + 3 * static_cast<std::size_t>(row_cols_[static_cast<std::size_t>(p)]);
      a0 += l * yj[0];
      a1 += l * yj[1];
      a2 += l * yj[2];
    }
    y[3 * i] -= a0;
    y[3 * i + 1] -= a1;
    y[3 * i + 2] -= a2;
  }
  for (std::size_t i = 0; i < n; ++i) {
    y[3 * i] *= inv_d_[i];
    y[3 * i + 1] *= inv_d_[i];
    y[3 * i + 2] *= inv_d_[i];
  }
  // Backward: L^T x = y, column by column from the end.
  for (std::size_t j = n; j-- > 0;) {
    double a0 = 0, a1 = 0, a2 = 0;
    for (std::int32_t p = col_ptr_[j]; p < col_ptr_[j + 1]; ++p) {
      const double l = upper_values_[static_cast<std::size_t>(p)];
      const double* yi = y + 3 * static_cast<std::size_t>(col_rows_[static_cast<std::size_t>(p)]);
      a0 += l * yi[0];
      a1 += l * yi[1];
      a2 += l * yi[2];
    }
    y[3 * j] -= a0;
    y[3 * j + 1] -= a1;
    y[3 * j + 2] -= a2;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t q = static_cast<std::size_t>(scatter_[i]) * 3;
    x[3 * i] = static_cast<float>(y[q]);
    x[3 * i + 1] = static_cast<float>(y[q + 1]);
    x[3 * i + 2] = static_cast<float>(y[q + 2]);
  }
}

}  // namespace softdeca::runtime
