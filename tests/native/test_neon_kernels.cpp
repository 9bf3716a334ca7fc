// The NEON kernels (aarch64) against the portable ones on the same stored values: hyper-tensor
// contraction in half, float and int8 storage (the DT right-hand side and vertex offsets) and the
// prefactored solve's substitution loops. Elsewhere the suite skips; the portable family itself
// runs on arm64 too (tests/platforms/arm64-check.sh sets SOFTDECA_CPU=portable).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/cpu_features.h"
#include "geometry/sparse_ldlt_neon.h"
#include "kernels/hypertensor.h"
#include "kernels/hypertensor_neon.h"

namespace {
using namespace softdeca::kernels;

TEST(NeonKernels, AreChosenOnEveryAarch64UnlessCapped) {
#ifdef SOFTDECA_NEON
  const bool portable = softdeca::cpu_features().neon == false;
  EXPECT_EQ(kernel_available(Kernel::Neon), !portable);
  EXPECT_STREQ(softdeca::cpu_family_name(), portable ? "portable" : "neon");
#else
  EXPECT_FALSE(kernel_available(Kernel::Neon));
#endif
  EXPECT_FALSE(softdeca::capped({false, false, true}, softdeca::CpuCap::Portable).neon);
  EXPECT_TRUE(softdeca::capped({false, false, true}, softdeca::CpuCap::Neon).neon);
  EXPECT_FALSE(softdeca::capped({true, true, false}, softdeca::CpuCap::Neon).avx2);
}

// Faces of a strip over n vertices, in FaceBlocks form with random corners and coefficients.
FaceBlocks random_faces(std::size_t faces, std::size_t vertices, std::mt19937& rng) {
  FaceBlocks fb;
  fb.blocks = (faces + kLanes - 1) / kLanes;
  fb.corners.resize(fb.blocks * 3 * kLanes);
  fb.coeff.resize(fb.blocks * 3 * kLanes);
  std::uniform_int_distribution<std::int32_t> vertex(0, static_cast<std::int32_t>(vertices) - 1);
  std::uniform_real_distribution<float> u(-1, 1);
  for (std::size_t b = 0; b < fb.blocks; ++b)
    for (std::size_t l = 0; l < kLanes; ++l) {
      const bool real = b * kLanes + l < faces;
      for (int c = 0; c < 3; ++c) {
        fb.corners[(b * 3 + static_cast<std::size_t>(c)) * kLanes + l] = real ? vertex(rng) : 0;
        fb.coeff[(b * 3 + static_cast<std::size_t>(c)) * kLanes + l] = real ? u(rng) : 0.0f;
      }
    }
  return fb;
}

double largest(const std::vector<float>& v) {
  double m = 0;
  for (float x : v) m = std::max(m, std::fabs(double(x)));
  return m;
}

// Both families read the same stored values; half and float differ by the order of float
// roundings only, int8 by the portable loop's per-term rounding against exact integer sums.
double parity_tolerance(Precision p) { return p == Precision::Int8 ? 2e-5 : 2e-6; }

TEST(NeonKernels, HyperTensorProductsMatchThePortableOnes) {
  if (!kernel_available(Kernel::Neon)) GTEST_SKIP() << "no NEON kernels on this CPU (or SOFTDECA_CPU caps them)";
  std::mt19937 rng(3);
  std::normal_distribution<float> nd;
  for (const int K : {32, 7}) {  // 7: an odd count, int8 pads it to pairs
    const std::size_t faces = 45, vertices = 29;  // neither a multiple of the block size
    std::vector<float> Lf(faces * K * 9), Lv(vertices * K * 3), z(K), skin(3 * vertices), base(3 * vertices);
    for (auto& x : Lf) x = 0.05f * nd(rng);
    for (auto& x : Lv) x = 0.001f * nd(rng);
    for (auto& x : z) x = nd(rng);
    for (auto& x : skin) x = 0.1f * nd(rng);
    for (auto& x : base) x = nd(rng);
    const FaceBlocks fb = random_faces(faces, vertices, rng);
    for (const Precision p : {Precision::Half, Precision::Float, Precision::Int8}) {
      const HyperTensor tf(Lf.data(), faces, K, 9, p), tv(Lv.data(), vertices, K, 3, p);
      std::vector<float> rhs_neon(kRhsStride * vertices, 0.0f), rhs_portable(kRhsStride * vertices, 0.0f);
      dg_rhs(tf, fb, z.data(), skin.data(), 0, tf.blocks(), rhs_neon.data(), Kernel::Neon);
      dg_rhs(tf, fb, z.data(), skin.data(), 0, tf.blocks(), rhs_portable.data(), Kernel::Portable);
      const double scale = largest(rhs_portable);
      for (std::size_t i = 0; i < rhs_neon.size(); ++i)
        EXPECT_NEAR(rhs_neon[i], rhs_portable[i], parity_tolerance(p) * scale) << "K " << K << " precision " << int(p);
      std::vector<float> out_neon(3 * vertices + 3, -7.0f), out_portable(3 * vertices + 3, -7.0f);
      vertex_offsets(tv, z.data(), base.data(), 0, tv.blocks(), out_neon.data(), Kernel::Neon);
      vertex_offsets(tv, z.data(), base.data(), 0, tv.blocks(), out_portable.data(), Kernel::Portable);
      for (std::size_t i = 0; i < out_neon.size(); ++i)
        EXPECT_NEAR(out_neon[i], out_portable[i], 1e-6) << "K " << K << " precision " << int(p) << " value " << i;
    }
  }
}

#ifdef SOFTDECA_LDLT_NEON
// The substitution loops against the same loops written plainly (sparse_ldlt.cpp's portable ones).
TEST(NeonKernels, SubstitutionMatchesThePlainLoops) {
  const std::size_t n = 300;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1, 1);
  std::uniform_int_distribution<std::int32_t> count(0, 11);
  std::vector<std::int32_t> ptr{0}, idx32, rows;
  std::vector<float> values;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::int32_t k = count(rng); k > 0; --k) {
      idx32.push_back(std::uniform_int_distribution<std::int32_t>(0, static_cast<std::int32_t>(n) - 1)(rng));
      values.push_back(u(rng));
    }
    ptr.push_back(static_cast<std::int32_t>(idx32.size()));
    rows.push_back(static_cast<std::int32_t>(i));
  }
  const std::vector<std::uint16_t> idx16(idx32.begin(), idx32.end());
  std::vector<double> y0(4 * n);
  for (auto& x : y0) x = u(rng);
  // substitute: y[i] -= sum_p values[p] y[idx[p]], rows in order.
  std::vector<double> want = y0, got16 = y0, got32 = y0;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      double a = 0;
      for (std::int32_t p = ptr[i]; p < ptr[i + 1]; ++p) a += double(values[std::size_t(p)]) * want[4 * std::size_t(idx32[std::size_t(p)]) + c];
      want[4 * i + c] -= a;
    }
  softdeca::geometry::neon::substitute(rows.data(), n, ptr.data(), idx16.data(), values.data(), got16.data());
  softdeca::geometry::neon::substitute(rows.data(), n, ptr.data(), idx32.data(), values.data(), got32.data());
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(got16[4 * i + c], want[4 * i + c], 1e-9 * (1 + std::fabs(want[4 * i + c])));
      EXPECT_EQ(got16[4 * i + c], got32[4 * i + c]);
    }
  // scatter: for each column j, y[i] -= L[i, j] y[j] over its rows.
  want = y0;
  std::vector<double> got = y0;
  for (std::size_t j = 0; j < n; ++j) {
    const double yj[3] = {want[4 * j], want[4 * j + 1], want[4 * j + 2]};  // read once, as the solve does
    for (std::int32_t p = ptr[j]; p < ptr[j + 1]; ++p)
      for (int c = 0; c < 3; ++c) want[4 * std::size_t(idx32[std::size_t(p)]) + c] -= double(values[std::size_t(p)]) * yj[c];
  }
  softdeca::geometry::neon::scatter(rows.data(), n, ptr.data(), idx32.data(), values.data(), got.data());
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[4 * i + c], want[4 * i + c], 1e-9 * (1 + std::fabs(want[4 * i + c])));
}
#endif

}  // namespace
