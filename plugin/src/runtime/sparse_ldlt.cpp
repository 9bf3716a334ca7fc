#include "runtime/sparse_ldlt.h"

#include <Eigen/SparseCholesky>

#include <cmath>
#include <string>

#include "api/error.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SOFTDECA_X86 1
#endif

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
    const std::int32_t pi = p.size() ? p[static_cast<Eigen::Index>(i)] : static_cast<std::int32_t>(i);
    gather_[static_cast<std::size_t>(pi)] = static_cast<std::int32_t>(i);
    scatter_[i] = pi;
  }
  Eigen::SparseMatrix<double> L = ldlt.matrixL();
  L.prune([](Eigen::Index r, Eigen::Index c, double) { return r > c; });
  L.makeCompressed();
  Eigen::SparseMatrix<double, Eigen::RowMajor> R = L;
  R.makeCompressed();
  const std::size_t nnz = static_cast<std::size_t>(L.nonZeros());
  col_ptr_.assign(L.outerIndexPtr(), L.outerIndexPtr() + L.outerSize() + 1);
  row_ptr_.assign(R.outerIndexPtr(), R.outerIndexPtr() + R.outerSize() + 1);
  values_upper_.assign(L.valuePtr(), L.valuePtr() + nnz);
  values_lower_.assign(R.valuePtr(), R.valuePtr() + nnz);
  if (n_ <= 65536) {
    col_rows16_.assign(L.innerIndexPtr(), L.innerIndexPtr() + nnz);
    row_cols16_.assign(R.innerIndexPtr(), R.innerIndexPtr() + nnz);
  } else {
    col_rows32_.assign(L.innerIndexPtr(), L.innerIndexPtr() + nnz);
    row_cols32_.assign(R.innerIndexPtr(), R.innerIndexPtr() + nnz);
  }
}

std::size_t SparseLdlt::bytes() const {
  return (gather_.size() + scatter_.size() + row_ptr_.size() + col_ptr_.size()) * 4 + inv_d_.size() * 8 +
         (row_cols16_.size() + col_rows16_.size()) * 2 + (row_cols32_.size() + col_rows32_.size()) * 4 +
         (values_lower_.size() + values_upper_.size()) * 4;
}

namespace {
// sum_p values[p] * y[4 idx[p] .. +3] over [b, e): four independent accumulators hide latency.
template <class Index>
inline void dot_portable(const Index* idx, const float* val, std::int32_t b, std::int32_t e, const double* y, double out[3]) {
  double a[4][3] = {};
  std::int32_t p = b;
  for (; p + 4 <= e; p += 4)
    for (int u = 0; u < 4; ++u) {
      const double l = val[p + u];
      const double* yj = y + 4 * static_cast<std::size_t>(idx[p + u]);
      a[u][0] += l * yj[0];
      a[u][1] += l * yj[1];
      a[u][2] += l * yj[2];
    }
  for (; p < e; ++p) {
    const double l = val[p];
    const double* yj = y + 4 * static_cast<std::size_t>(idx[p]);
    a[0][0] += l * yj[0];
    a[0][1] += l * yj[1];
    a[0][2] += l * yj[2];
  }
  for (int c = 0; c < 3; ++c) out[c] = (a[0][c] + a[1][c]) + (a[2][c] + a[3][c]);
}

#ifdef SOFTDECA_X86
template <class Index>
__attribute__((target("avx2,fma"))) inline __m256d dot_avx2(const Index* idx, const float* val, std::int32_t b, std::int32_t e,
                                                           const double* y) {
  __m256d a0 = _mm256_setzero_pd(), a1 = a0, a2 = a0, a3 = a0;
  std::int32_t p = b;
  for (; p + 4 <= e; p += 4) {
    a0 = _mm256_fmadd_pd(_mm256_set1_pd(val[p]), _mm256_load_pd(y + 4 * static_cast<std::size_t>(idx[p])), a0);
    a1 = _mm256_fmadd_pd(_mm256_set1_pd(val[p + 1]), _mm256_load_pd(y + 4 * static_cast<std::size_t>(idx[p + 1])), a1);
    a2 = _mm256_fmadd_pd(_mm256_set1_pd(val[p + 2]), _mm256_load_pd(y + 4 * static_cast<std::size_t>(idx[p + 2])), a2);
    a3 = _mm256_fmadd_pd(_mm256_set1_pd(val[p + 3]), _mm256_load_pd(y + 4 * static_cast<std::size_t>(idx[p + 3])), a3);
  }
  for (; p < e; ++p)
    a0 = _mm256_fmadd_pd(_mm256_set1_pd(val[p]), _mm256_load_pd(y + 4 * static_cast<std::size_t>(idx[p])), a0);
  return _mm256_add_pd(_mm256_add_pd(a0, a1), _mm256_add_pd(a2, a3));
}

template <class Index>
__attribute__((target("avx2,fma"))) void substitute_avx2(std::size_t n, const std::int32_t* row_ptr, const Index* row_cols,
                                                        const float* lower, const double* inv_d, const std::int32_t* col_ptr,
                                                        const Index* col_rows, const float* upper, double* y) {
  for (std::size_t i = 0; i < n; ++i) {
    const __m256d a = dot_avx2(row_cols, lower, row_ptr[i], row_ptr[i + 1], y);
    _mm256_store_pd(y + 4 * i, _mm256_sub_pd(_mm256_load_pd(y + 4 * i), a));
  }
  for (std::size_t i = 0; i < n; ++i) _mm256_store_pd(y + 4 * i, _mm256_mul_pd(_mm256_load_pd(y + 4 * i), _mm256_set1_pd(inv_d[i])));
  for (std::size_t j = n; j-- > 0;) {
    const __m256d a = dot_avx2(col_rows, upper, col_ptr[j], col_ptr[j + 1], y);
    _mm256_store_pd(y + 4 * j, _mm256_sub_pd(_mm256_load_pd(y + 4 * j), a));
  }
}

bool cpu_has_avx2_fma() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}
#endif
}  // namespace

template <class Index>
void SparseLdlt::substitute(const Index* row_cols, const Index* col_rows, double* y) const {
#ifdef SOFTDECA_X86
  if (cpu_has_avx2_fma()) {
    substitute_avx2(n_, row_ptr_.data(), row_cols, values_lower_.data(), inv_d_.data(), col_ptr_.data(), col_rows,
                    values_upper_.data(), y);
    return;
  }
#endif
  double a[3];
  for (std::size_t i = 0; i < n_; ++i) {  // forward: L y = P b, row by row
    dot_portable(row_cols, values_lower_.data(), row_ptr_[i], row_ptr_[i + 1], y, a);
    for (int c = 0; c < 3; ++c) y[4 * i + c] -= a[c];
  }
  for (std::size_t i = 0; i < n_; ++i)
    for (int c = 0; c < 3; ++c) y[4 * i + c] *= inv_d_[i];
  for (std::size_t j = n_; j-- > 0;) {  // backward: L^T x = D^-1 y, column by column
    dot_portable(col_rows, values_upper_.data(), col_ptr_[j], col_ptr_[j + 1], y, a);
    for (int c = 0; c < 3; ++c) y[4 * j + c] -= a[c];
  }
}

void SparseLdlt::solve(const float* const* b, std::size_t count, double* y, float* x) const {
  for (std::size_t q = 0; q < n_; ++q) {
    const std::size_t s = static_cast<std::size_t>(gather_[q]) * 3;
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (std::size_t k = 0; k < count; ++k) sum += b[k][s + c];
      y[4 * q + c] = sum;
    }
    y[4 * q + 3] = 0.0;
  }
  if (n_ <= 65536) substitute(row_cols16_.data(), col_rows16_.data(), y);
  else substitute(row_cols32_.data(), col_rows32_.data(), y);
  for (std::size_t i = 0; i < n_; ++i) {
    const std::size_t q = static_cast<std::size_t>(scatter_[i]) * 4;
    x[3 * i] = static_cast<float>(y[q]);
    x[3 * i + 1] = static_cast<float>(y[q + 1]);
    x[3 * i + 2] = static_cast<float>(y[q + 2]);
  }
}

}  // namespace softdeca::runtime
