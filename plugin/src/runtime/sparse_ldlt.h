// A prefactored symmetric positive definite solve for three right-hand sides at once.
// Eigen's SimplicialLDLT (AMD ordering) factorises P K P^T = L D L^T once; the factor is kept
// twice, row-major for the forward and column-major for the backward substitution, so both
// passes stream their part in order and gather from one xyz(w) vector that stays in L2.
// Factor values are stored as float and indices as uint16 when the size allows (accumulation
// is in double): the solve is bound by the bytes it reads, and this halves them at a relative
// error of ~1e-7 (measured against double values, tests/native/test_runtime_math.cpp).
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
  std::size_t factor_nonzeros() const { return values_lower_.size(); }
  std::size_t bytes() const;

  // x = K^-1 (b[0] + ... + b[count-1]), xyz interleaved (n x 3); the right-hand side comes in
  // parts (one per thread). `work`: work_size() doubles.
  void solve(const float* const* b, std::size_t count, double* work, float* x) const;
  std::size_t work_size() const { return 4 * n_; }

 private:
  template <class Index>
  void substitute(const Index* row_cols, const Index* col_rows, double* y) const;

  std::size_t n_ = 0;
  std::vector<std::int32_t> gather_, scatter_;  // y[q] = b[gather_[q]]; x[i] = y[scatter_[i]]
  std::vector<double> inv_d_;
  std::vector<std::int32_t> row_ptr_, col_ptr_;
  std::vector<std::uint16_t> row_cols16_, col_rows16_;  // when n <= 65536
  std::vector<std::uint32_t> row_cols32_, col_rows32_;  // otherwise
  std::vector<float> values_lower_, values_upper_;     // strict lower L, row- and column-major
};

}  // namespace softdeca::runtime
