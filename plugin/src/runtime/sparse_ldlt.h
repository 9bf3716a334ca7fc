// A prefactored symmetric positive definite solve for three right-hand sides at once.
// Eigen's SimplicialLDLT (AMD ordering) factorises P K P^T = L D L^T once; the factor is then
// kept twice, row-major for the forward and column-major for the backward substitution, so
// both passes stream their factor in order and gather from one interleaved xyz vector.
#pragma once

#include <Eigen/SparseCore>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "runtime/aligned.h"

namespace softdeca::runtime {

class SparseLdlt {
 public:
  // Throws Error(SOFTDECA_ERROR_INVALID_ARGUMENT) when K is not positive definite.
  explicit SparseLdlt(const Eigen::SparseMatrix<double>& K);

  std::size_t size() const { return n_; }
  std::size_t factor_nonzeros() const { return lower_values_.size(); }
  std::size_t bytes() const;

  // x = K^-1 (b0 + b1), xyz interleaved (n x 3). b1 may be null. `work` holds 3n doubles.
  // x may alias neither b0 nor b1.
  void solve(const float* b0, const float* b1, double* work, float* x) const;

 private:
  std::size_t n_ = 0;
  std::vector<std::int32_t> gather_, scatter_;  // y[q] = b[gather_[q]]; x[i] = y[scatter_[i]]
  std::vector<double> inv_d_;
  // Strictly lower L, row-major (forward) and column-major (backward).
  std::vector<std::int32_t> row_ptr_, row_cols_, col_ptr_, col_rows_;
  std::vector<double> lower_values_, upper_values_;
};

}  // namespace softdeca::runtime
