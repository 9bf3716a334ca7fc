// A prefactored symmetric positive definite solve for three right-hand sides at once.
// The shared LDL^T factorisation (geometry/ldlt_factor.h) factorises
// P K P^T = L D L^T once; the factor is kept column-major: the backward substitution gathers
// (a dot product per column), the forward one scatters (an axpy per column, two rows per
// instruction with AVX-512), both streaming the factor in order over one xyz(w) vector that
// stays in L2. One copy serves both passes, so the backward pass finds in cache what the forward
// one read: a row-major copy for a gathering forward pass was faster alone and slower in a
// frame (docs/performance-notes.md). With several threads the forward pass does gather from a
// second, row-major copy (no two threads write one row). Factor values are stored as float and
// indices as uint16 when the size allows (accumulation is in double), a relative error of
// ~1e-7 (measured against double values, tests/native/test_runtime_math.cpp).
// Threads: the elimination tree splits into independent subtrees below a small top part; both
// substitutions run the subtrees in parallel (one per part) and the top part alone.
#pragma once

#include <Eigen/SparseCore>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/aligned.h"

namespace softdeca::geometry {

class SparseLdlt {
 public:
  // Throws Error(SOFTDECA_ERROR_INVALID_ARGUMENT) when K is not positive definite. `parts`:
  // how many threads will run solve_part.
  explicit SparseLdlt(const Eigen::SparseMatrix<double>& K, std::size_t parts = 1);

  std::size_t size() const { return n_; }
  std::size_t factor_nonzeros() const { return nnz_; }
  std::size_t bytes() const;  // the factor and the schedule
  std::size_t solve_bytes() const;  // what a solve reads: the factor's values, indices and diagonal

  // x = K^-1 (b[0] + ... + b[count-1]): x is xyz interleaved (n x 3), each b is n x 4 (x, y, z
  // and a lane not read, so that a right-hand side is added to 16 bytes at a time); the
  // right-hand side comes in parts (one per thread). `work`: work_size() doubles. Single-threaded.
  void solve(const float* const* b, std::size_t count, double* work, float* x) const;
  std::size_t work_size() const { return 4 * n_; }

  // x = base + K^-1 (...) in phases for `parts()` threads: run phase p on every part
  // (0..parts-1, in parallel) before phase p + 1. The top part runs on part 0. base may be null.
  static constexpr int kPhases = 3;
  std::size_t parts() const { return bins_.size(); }
  void solve_phase(int phase, std::size_t part, const float* const* b, std::size_t count, double* work, const float* base,
                   float* x) const;
  double serial_fraction() const { return serial_fraction_; }  // of the factor's nonzeros

 private:
  void gather(const std::vector<std::int32_t>& rows, const float* const* b, std::size_t count, double* y) const;
  void scale(const std::vector<std::int32_t>& rows, double* y) const;
  void write(const std::vector<std::int32_t>& rows, const double* y, const float* base, float* x) const;
  void forward(const std::vector<std::int32_t>& rows, double* y) const;
  void backward(const std::vector<std::int32_t>& rows, double* y) const;  // rows descending
  void schedule(std::size_t parts);

  std::size_t n_ = 0;
  std::vector<std::int32_t> gather_;  // y[q] = b[gather_[q]]; x[gather_[q]] = y[q]
  std::vector<double> inv_d_;
  std::vector<std::int32_t> row_ptr_, col_ptr_;
  std::vector<std::uint16_t> row_cols16_, col_rows16_;  // when n <= 65536
  std::vector<std::uint32_t> row_cols32_, col_rows32_;  // otherwise
  std::size_t nnz_ = 0;
  // Strict lower L, column-major ([0, nnz)) and, with several parts, row-major ([nnz, 2 nnz));
  // one array so that it is one huge-page stream (aligned.h).
  bool rows_copy_ = false;
  kernels::AlignedArray<float> values_;
  std::vector<std::vector<std::int32_t>> bins_, bins_down_;  // rows of independent subtrees, up and down
  std::vector<std::int32_t> top_, top_down_;                 // the top part, up and down
  double serial_fraction_ = 0;
};

}  // namespace softdeca::geometry
