#include "geometry/sparse_ldlt.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/cpu_features.h"
#include "core/error.h"
#include "geometry/ldlt_factor.h"
#include "geometry/sparse_ldlt_neon.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SOFTDECA_X86 1
#endif

namespace softdeca::geometry {

SparseLdlt::SparseLdlt(const Eigen::SparseMatrix<double>& K, std::size_t parts) : n_(static_cast<std::size_t>(K.rows())) {
  const LdltFactor ldlt(K);
  require(ldlt.ok(), "the deformation-transfer matrix cannot be factorised");
  const Eigen::VectorXd& d = ldlt.diagonal();
  inv_d_.resize(n_);
  for (std::size_t i = 0; i < n_; ++i) {
    const double v = d[static_cast<Eigen::Index>(i)];
    require(v > 0 && std::isfinite(v), "the deformation-transfer matrix is not positive definite (pivot " +
                                           std::to_string(i) + ")");
    inv_d_[i] = 1.0 / v;
  }
  // Eigen: P b puts b[i] at P.indices()[i].
  const auto& p = ldlt.permutation().indices();
  gather_.resize(n_);
  for (std::size_t i = 0; i < n_; ++i) {
    const std::int32_t pi = p.size() ? p[static_cast<Eigen::Index>(i)] : static_cast<std::int32_t>(i);
    gather_[static_cast<std::size_t>(pi)] = static_cast<std::int32_t>(i);
  }
  Eigen::SparseMatrix<double> L = ldlt.lower();
  L.prune([](Eigen::Index r, Eigen::Index c, double) { return r > c; });
  L.makeCompressed();
  Eigen::SparseMatrix<double, Eigen::RowMajor> R = L;
  R.makeCompressed();
  const std::size_t nnz = static_cast<std::size_t>(L.nonZeros());
  col_ptr_.assign(L.outerIndexPtr(), L.outerIndexPtr() + L.outerSize() + 1);
  row_ptr_.assign(R.outerIndexPtr(), R.outerIndexPtr() + R.outerSize() + 1);
  nnz_ = nnz;
  // One thread: the forward pass scatters by columns, so the column-major copy serves both
  // passes. Several: the forward pass gathers by rows (a column of one subtree may update a
  // row of the top part that another thread's column updates too), so it keeps a row-major copy.
  rows_copy_ = parts > 1;
  values_.resize((rows_copy_ ? 2 : 1) * nnz);
  std::copy(L.valuePtr(), L.valuePtr() + nnz, values_.data());
  if (rows_copy_) std::copy(R.valuePtr(), R.valuePtr() + nnz, values_.data() + nnz);
  if (n_ <= 65536) {
    col_rows16_.assign(L.innerIndexPtr(), L.innerIndexPtr() + nnz);
    if (rows_copy_) row_cols16_.assign(R.innerIndexPtr(), R.innerIndexPtr() + nnz);
  } else {
    col_rows32_.assign(L.innerIndexPtr(), L.innerIndexPtr() + nnz);
    if (rows_copy_) row_cols32_.assign(R.innerIndexPtr(), R.innerIndexPtr() + nnz);
  }
  schedule(parts < 1 ? 1 : parts);
}

void SparseLdlt::schedule(std::size_t parts) {
  // Elimination tree: the parent of column j is its first off-diagonal row. Row i of the
  // forward pass reads only rows of its subtree; column j of the backward pass only ancestors.
  const std::size_t n = n_;
  std::vector<std::int32_t> parent(n, -1);
  std::vector<double> weight(n), subtree(n);
  for (std::size_t j = 0; j < n; ++j) {
    const std::int32_t b = col_ptr_[j], e = col_ptr_[j + 1];
    if (e > b) parent[j] = static_cast<std::int32_t>(n <= 65536 ? col_rows16_[static_cast<std::size_t>(b)] : col_rows32_[static_cast<std::size_t>(b)]);
    weight[j] = 1.0 + (e - b) + (row_ptr_[j + 1] - row_ptr_[j]);
  }
  subtree = weight;
  for (std::size_t j = 0; j < n; ++j)
    if (parent[j] >= 0) subtree[static_cast<std::size_t>(parent[j])] += subtree[j];
  std::vector<std::vector<std::int32_t>> children(n);
  std::vector<std::int32_t> front;
  double total = 0;
  for (std::size_t j = 0; j < n; ++j) {
    if (parent[j] >= 0) children[static_cast<std::size_t>(parent[j])].push_back(static_cast<std::int32_t>(j));
    else front.push_back(static_cast<std::int32_t>(j)), total += subtree[j];
  }
  // Open the heaviest subtree into its children (its root joins the top part) until the front
  // splits into `parts` bins of nearly equal weight, or the top part grows too large.
  std::vector<char> top(n, 0);
  double top_weight = 0;
  std::vector<std::size_t> bin_of_front;
  for (;;) {
    std::sort(front.begin(), front.end(), [&](std::int32_t a, std::int32_t b) { return subtree[static_cast<std::size_t>(a)] > subtree[static_cast<std::size_t>(b)]; });
    std::vector<double> load(parts, 0.0);
    bin_of_front.assign(front.size(), 0);
    for (std::size_t f = 0; f < front.size(); ++f) {
      const std::size_t lightest = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
      load[lightest] += subtree[static_cast<std::size_t>(front[f])];
      bin_of_front[f] = lightest;
    }
    const double rest = total - top_weight, heaviest = *std::max_element(load.begin(), load.end());
    if (parts == 1 || front.empty() || heaviest <= 1.05 * rest / static_cast<double>(parts) || top_weight > 0.35 * total) break;
    const std::int32_t open = front.front();
    if (children[static_cast<std::size_t>(open)].empty()) break;
    front.erase(front.begin());
    top[static_cast<std::size_t>(open)] = 1;
    top_weight += weight[static_cast<std::size_t>(open)];
    for (const std::int32_t c : children[static_cast<std::size_t>(open)]) front.push_back(c);
  }
  // Every row below the top part belongs to the bin of its front ancestor.
  std::vector<std::int32_t> bin(n, -1);
  for (std::size_t f = 0; f < front.size(); ++f) bin[static_cast<std::size_t>(front[f])] = static_cast<std::int32_t>(bin_of_front[f]);
  for (std::size_t j = n; j-- > 0;)  // parents come after children: walk down from the roots
    if (!top[j] && bin[j] < 0 && parent[j] >= 0) bin[j] = bin[static_cast<std::size_t>(parent[j])];
  bins_.assign(parts, {});
  top_.clear();
  for (std::size_t j = 0; j < n; ++j) {
    if (top[j]) top_.push_back(static_cast<std::int32_t>(j));
    else bins_[static_cast<std::size_t>(bin[j] < 0 ? 0 : bin[j])].push_back(static_cast<std::int32_t>(j));
  }
  top_down_.assign(top_.rbegin(), top_.rend());
  bins_down_.clear();
  for (const auto& b : bins_) bins_down_.emplace_back(b.rbegin(), b.rend());
  serial_fraction_ = total > 0 ? top_weight / total : 0.0;
}

std::size_t SparseLdlt::solve_bytes() const {
  // The row-major copy (values, row_ptr_, row_cols) only exists, or is read, with several parts.
  return (gather_.size() + col_ptr_.size() + (rows_copy_ ? row_ptr_.size() : 0)) * 4 + inv_d_.size() * 8 +
         (row_cols16_.size() + col_rows16_.size()) * 2 + (row_cols32_.size() + col_rows32_.size()) * 4 + values_.bytes();
}

std::size_t SparseLdlt::bytes() const {
  return solve_bytes() + (rows_copy_ ? 0 : row_ptr_.size() * 4) + values_.allocated_bytes() - values_.bytes();
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
    a0 = _mm256_fmadd_pd(_mm256_set1_pd(val[p]), _mm256_loadu_pd(y + 4 * static_cast<std::size_t>(idx[p])), a0);
    a1 = _mm256_fmadd_pd(_mm256_set1_pd(val[p + 1]), _mm256_loadu_pd(y + 4 * static_cast<std::size_t>(idx[p + 1])), a1);
    a2 = _mm256_fmadd_pd(_mm256_set1_pd(val[p + 2]), _mm256_loadu_pd(y + 4 * static_cast<std::size_t>(idx[p + 2])), a2);
    a3 = _mm256_fmadd_pd(_mm256_set1_pd(val[p + 3]), _mm256_loadu_pd(y + 4 * static_cast<std::size_t>(idx[p + 3])), a3);
  }
  for (; p < e; ++p)
    a0 = _mm256_fmadd_pd(_mm256_set1_pd(val[p]), _mm256_loadu_pd(y + 4 * static_cast<std::size_t>(idx[p])), a0);
  return _mm256_add_pd(_mm256_add_pd(a0, a1), _mm256_add_pd(a2, a3));
}

// y[i] -= sum_p values[p] y[idx[p]] over the rows in `rows` (in the given order).
template <class Index>
__attribute__((target("avx2,fma"))) void substitute_avx2(const std::int32_t* rows, std::size_t count, const std::int32_t* ptr,
                                                        const Index* idx, const float* values, double* y) {
  for (std::size_t r = 0; r < count; ++r) {
    const std::size_t i = static_cast<std::size_t>(rows[r]);
    const __m256d a = dot_avx2(idx, values, ptr[i], ptr[i + 1], y);
    _mm256_storeu_pd(y + 4 * i, _mm256_sub_pd(_mm256_loadu_pd(y + 4 * i), a));
  }
}

// Column form of the forward pass: for each column j of `cols` (in elimination order), y[j] is
// final; y[i] -= L[i, j] y[j] for the rows i of column j.
template <class Index>
__attribute__((target("avx2,fma"))) void scatter_avx2(const std::int32_t* cols, std::size_t count, const std::int32_t* ptr,
                                                     const Index* idx, const float* values, double* y) {
  for (std::size_t r = 0; r < count; ++r) {
    const std::size_t j = static_cast<std::size_t>(cols[r]);
    const __m256d yj = _mm256_loadu_pd(y + 4 * j);
    for (std::int32_t p = ptr[j]; p < ptr[j + 1]; ++p) {
      double* yi = y + 4 * static_cast<std::size_t>(idx[p]);
      _mm256_storeu_pd(yi, _mm256_fnmadd_pd(_mm256_set1_pd(values[p]), yj, _mm256_loadu_pd(yi)));
    }
  }
}

// The same with AVX-512: two rows of the column per fused multiply-add, half the instructions
// per factor value (the solve 0.05 ms faster in a frame, docs/performance-notes.md). GCC 12's
// own AVX-512 headers fill the unused upper lanes of these casts and inserts with
// _mm512_undefined_pd, which -Wmaybe-uninitialized reports.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
template <class Index>
__attribute__((target("avx512f,avx512vl,avx2,fma"))) void scatter_avx512(const std::int32_t* cols, std::size_t count,
                                                                       const std::int32_t* ptr, const Index* idx,
                                                                       const float* values, double* y) {
  const __m512i pairs = _mm512_set_epi64(1, 1, 1, 1, 0, 0, 0, 0);
  for (std::size_t r = 0; r < count; ++r) {
    const std::size_t j = static_cast<std::size_t>(cols[r]);
    const __m256d yj4 = _mm256_loadu_pd(y + 4 * j);
    const __m512d yj = _mm512_insertf64x4(_mm512_castpd256_pd512(yj4), yj4, 1);
    std::int32_t p = ptr[j];
    const std::int32_t e = ptr[j + 1];
    for (; p + 2 <= e; p += 2) {
      double* ya = y + 4 * static_cast<std::size_t>(idx[p]);
      double* yb = y + 4 * static_cast<std::size_t>(idx[p + 1]);
      const __m512d both = _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_loadu_pd(ya)), _mm256_loadu_pd(yb), 1);
      const __m128 lv = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(values + p)));
      const __m512d l = _mm512_permutexvar_pd(pairs, _mm512_castpd128_pd512(_mm_cvtps_pd(lv)));
      const __m512d out = _mm512_fnmadd_pd(l, yj, both);
      _mm256_storeu_pd(ya, _mm512_castpd512_pd256(out));
      _mm256_storeu_pd(yb, _mm512_extractf64x4_pd(out, 1));
    }
    if (p < e) {
      double* yi = y + 4 * static_cast<std::size_t>(idx[p]);
      _mm256_storeu_pd(yi, _mm256_fnmadd_pd(_mm256_set1_pd(values[p]), yj4, _mm256_loadu_pd(yi)));
    }
  }
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

bool cpu_has_avx2_fma() { return cpu_features().avx2; }
bool cpu_has_avx512() { return cpu_features().avx512_vnni; }  // the AVX-512 family: F and VL with VNNI
#endif

template <class Index>
void substitute(const std::vector<std::int32_t>& rows, const std::vector<std::int32_t>& ptr, const Index* idx,
                const float* values, double* y) {
#ifdef SOFTDECA_X86
  if (cpu_has_avx2_fma()) {
    substitute_avx2(rows.data(), rows.size(), ptr.data(), idx, values, y);
    return;
  }
#endif
#ifdef SOFTDECA_LDLT_NEON
  if (cpu_features().neon) {
    neon::substitute(rows.data(), rows.size(), ptr.data(), idx, values, y);
    return;
  }
#endif
  double a[3];
  for (const std::int32_t r : rows) {
    const std::size_t i = static_cast<std::size_t>(r);
    dot_portable(idx, values, ptr[i], ptr[i + 1], y, a);
    for (int c = 0; c < 3; ++c) y[4 * i + c] -= a[c];
  }
}

template <class Index>
void scatter(const std::vector<std::int32_t>& cols, const std::vector<std::int32_t>& ptr, const Index* idx, const float* values,
             double* y) {
#ifdef SOFTDECA_X86
  if (cpu_has_avx512()) {
    scatter_avx512(cols.data(), cols.size(), ptr.data(), idx, values, y);
    return;
  }
  if (cpu_has_avx2_fma()) {
    scatter_avx2(cols.data(), cols.size(), ptr.data(), idx, values, y);
    return;
  }
#endif
#ifdef SOFTDECA_LDLT_NEON
  if (cpu_features().neon) {
    neon::scatter(cols.data(), cols.size(), ptr.data(), idx, values, y);
    return;
  }
#endif
  for (const std::int32_t c : cols) {
    const std::size_t j = static_cast<std::size_t>(c);
    const double yj[3] = {y[4 * j], y[4 * j + 1], y[4 * j + 2]};
    for (std::int32_t p = ptr[j]; p < ptr[j + 1]; ++p) {
      double* yi = y + 4 * static_cast<std::size_t>(idx[p]);
      const double l = values[p];
      yi[0] -= l * yj[0];
      yi[1] -= l * yj[1];
      yi[2] -= l * yj[2];
    }
  }
}

}  // namespace

void SparseLdlt::forward(const std::vector<std::int32_t>& rows, double* y) const {
  if (!rows_copy_) {
    if (n_ <= 65536) scatter(rows, col_ptr_, col_rows16_.data(), values_.data(), y);
    else scatter(rows, col_ptr_, col_rows32_.data(), values_.data(), y);
    return;
  }
  if (n_ <= 65536) substitute(rows, row_ptr_, row_cols16_.data(), values_.data() + nnz_, y);
  else substitute(rows, row_ptr_, row_cols32_.data(), values_.data() + nnz_, y);
}

void SparseLdlt::backward(const std::vector<std::int32_t>& rows, double* y) const {
  if (n_ <= 65536) substitute(rows, col_ptr_, col_rows16_.data(), values_.data(), y);
  else substitute(rows, col_ptr_, col_rows32_.data(), values_.data(), y);
}

void SparseLdlt::gather(const std::vector<std::int32_t>& rows, const float* const* b, std::size_t count, double* y) const {
  for (const std::int32_t r : rows) {
    const std::size_t q = static_cast<std::size_t>(r), s = static_cast<std::size_t>(gather_[q]) * 4;
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (std::size_t k = 0; k < count; ++k) sum += b[k][s + c];
      y[4 * q + c] = sum;
    }
    y[4 * q + 3] = 0.0;
  }
}

void SparseLdlt::scale(const std::vector<std::int32_t>& rows, double* y) const {
  for (const std::int32_t r : rows) {
    const std::size_t q = static_cast<std::size_t>(r);
    for (int c = 0; c < 3; ++c) y[4 * q + c] *= inv_d_[q];
  }
}

void SparseLdlt::write(const std::vector<std::int32_t>& rows, const double* y, const float* base, float* x) const {
  for (const std::int32_t r : rows) {  // row q of y is output vertex gather_[q]
    const std::size_t q = static_cast<std::size_t>(r), i = 3 * static_cast<std::size_t>(gather_[q]);
    for (int c = 0; c < 3; ++c) x[i + c] = static_cast<float>(y[4 * q + c] + (base ? base[i + c] : 0.0f));
  }
}

void SparseLdlt::solve_phase(int phase, std::size_t part, const float* const* b, std::size_t count, double* y,
                             const float* base, float* x) const {
  switch (phase) {
    case 0:  // this part's subtrees: right-hand side, forward pass
      gather(bins_[part], b, count, y);
      forward(bins_[part], y);
      break;
    case 1:  // the top part, alone: its forward pass (reads every subtree), D^-1, backward pass
      if (part != 0) break;
      gather(top_, b, count, y);
      forward(top_, y);
      scale(top_, y);
      backward(top_down_, y);
      write(top_, y, base, x);
      break;
    case 2:  // this part's subtrees: D^-1, backward pass (reads only ancestors), output
      scale(bins_[part], y);
      backward(bins_down_[part], y);
      write(bins_[part], y, base, x);
      break;
    default:
      break;
  }
}

void SparseLdlt::solve(const float* const* b, std::size_t count, double* y, float* x) const {
  for (int phase = 0; phase < kPhases; ++phase)
    for (std::size_t part = 0; part < bins_.size(); ++part) solve_phase(phase, part, b, count, y, nullptr, x);
}

}  // namespace softdeca::geometry
