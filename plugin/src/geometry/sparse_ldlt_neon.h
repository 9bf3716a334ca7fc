// The prefactored solve's substitution loops (sparse_ldlt.cpp) on aarch64's Advanced SIMD: the
// AVX2 loops' arithmetic with each right-hand side's 4 doubles (x, y, z, padding) as two 2-lane
// registers, the same fused multiply-adds in the same order. Included by sparse_ldlt.cpp only.
#pragma once

#if defined(__aarch64__) && defined(__ARM_NEON)
#define SOFTDECA_LDLT_NEON 1

#include <arm_neon.h>

#include <cstddef>
#include <cstdint>

namespace softdeca::geometry::neon {

// sum_p val[p] * y[4 idx[p] .. +3] over [b, e) into (lo, hi), four accumulators as the AVX2 dot.
template <class Index>
inline void dot(const Index* idx, const float* val, std::int32_t b, std::int32_t e, const double* y, float64x2_t& lo,
                float64x2_t& hi) {
  float64x2_t a[4][2];
  for (auto& acc : a) acc[0] = acc[1] = vdupq_n_f64(0.0);
  std::int32_t p = b;
  for (; p + 4 <= e; p += 4)
    for (int u = 0; u < 4; ++u) {
      const float64x2_t l = vdupq_n_f64(val[p + u]);
      const double* yj = y + 4 * static_cast<std::size_t>(idx[p + u]);
      a[u][0] = vfmaq_f64(a[u][0], l, vld1q_f64(yj));
      a[u][1] = vfmaq_f64(a[u][1], l, vld1q_f64(yj + 2));
    }
  for (; p < e; ++p) {
    const float64x2_t l = vdupq_n_f64(val[p]);
    const double* yj = y + 4 * static_cast<std::size_t>(idx[p]);
    a[0][0] = vfmaq_f64(a[0][0], l, vld1q_f64(yj));
    a[0][1] = vfmaq_f64(a[0][1], l, vld1q_f64(yj + 2));
  }
  lo = vaddq_f64(vaddq_f64(a[0][0], a[1][0]), vaddq_f64(a[2][0], a[3][0]));
  hi = vaddq_f64(vaddq_f64(a[0][1], a[1][1]), vaddq_f64(a[2][1], a[3][1]));
}

// y[i] -= sum_p values[p] y[idx[p]] over the rows in `rows` (in the given order).
template <class Index>
void substitute(const std::int32_t* rows, std::size_t count, const std::int32_t* ptr, const Index* idx, const float* values,
                double* y) {
  for (std::size_t r = 0; r < count; ++r) {
    const std::size_t i = static_cast<std::size_t>(rows[r]);
    float64x2_t lo, hi;
    dot(idx, values, ptr[i], ptr[i + 1], y, lo, hi);
    vst1q_f64(y + 4 * i, vsubq_f64(vld1q_f64(y + 4 * i), lo));
    vst1q_f64(y + 4 * i + 2, vsubq_f64(vld1q_f64(y + 4 * i + 2), hi));
  }
}

// The column form: for each column j of `cols`, y[i] -= L[i, j] y[j] for the rows i of column j.
template <class Index>
void scatter(const std::int32_t* cols, std::size_t count, const std::int32_t* ptr, const Index* idx, const float* values,
             double* y) {
  for (std::size_t r = 0; r < count; ++r) {
    const std::size_t j = static_cast<std::size_t>(cols[r]);
    const float64x2_t lo = vld1q_f64(y + 4 * j), hi = vld1q_f64(y + 4 * j + 2);
    for (std::int32_t p = ptr[j]; p < ptr[j + 1]; ++p) {
      double* yi = y + 4 * static_cast<std::size_t>(idx[p]);
      const float64x2_t l = vdupq_n_f64(values[p]);
      vst1q_f64(yi, vfmsq_f64(vld1q_f64(yi), l, lo));
      vst1q_f64(yi + 2, vfmsq_f64(vld1q_f64(yi + 2), l, hi));
    }
  }
}

}  // namespace softdeca::geometry::neon

#endif
