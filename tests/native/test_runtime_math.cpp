// The runtime's building blocks against direct computations: half conversion, the compact
// hyper-tensor kernels, the prefactored solve, blendshape runs, normals, rigid fits, dynamics,
// the worker, parameter states, and the manifest's JSON and tar readers.
#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "bundle/bundle_files.h"
#include "bundle/json.h"
#include "core/error.h"
#include "geometry/normals.h"
#include "geometry/rigid.h"
#include "geometry/sparse_ldlt.h"
#include "kernels/half.h"
#include "kernels/hypertensor.h"
#include "kernels/worker.h"
#include "prepare/parameters.h"
#include "runtime/blendshapes.h"
#include "runtime/deformation_transfer.h"
#include "runtime/dynamics.h"

namespace {
using namespace softdeca::bundle;
using namespace softdeca::kernels;
using namespace softdeca::prepare;
using namespace softdeca::runtime;
using namespace softdeca::geometry;

TEST(Half, RoundTripsAndRoundsToNearestEven) {
  EXPECT_EQ(float_to_half(1.0f), 0x3C00);
  EXPECT_EQ(float_to_half(-2.0f), 0xC000);
  EXPECT_EQ(float_to_half(65504.0f), 0x7BFF);
  EXPECT_EQ(float_to_half(1e6f), 0x7C00);  // overflow -> infinity
  EXPECT_EQ(float_to_half(5.9604645e-8f), 0x0001);  // smallest subnormal
  EXPECT_EQ(float_to_half(1.0f + 1.0f / 2048.0f), 0x3C00);  // halfway: to even
  EXPECT_EQ(float_to_half(1.0f + 3.0f / 2048.0f), 0x3C02);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-4.0f, 4.0f);
  for (int i = 0; i < 10000; ++i) {
    const float x = u(rng) * std::pow(10.0f, static_cast<float>(i % 7) - 4.0f);
    const float back = half_to_float(float_to_half(x));
    EXPECT_LE(std::fabs(back - x), std::max(std::fabs(x) * (1.0f / 2048.0f), 6e-8f)) << x;
  }
  for (uint32_t h = 0; h < 0x7C00; ++h) EXPECT_EQ(float_to_half(half_to_float(static_cast<uint16_t>(h))), h);
}

// A small mesh: a triangulated grid bent into a cap.
struct Grid {
  std::vector<float> v;
  std::vector<int32_t> t;
  std::size_t n = 0;
  explicit Grid(int k = 9) {
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        const float x = static_cast<float>(i) / (k - 1) - 0.5f, y = static_cast<float>(j) / (k - 1) - 0.5f;
        v.insert(v.end(), {0.1f * x, 0.1f * y, 0.02f * std::cos(2.0f * x) * std::cos(2.0f * y)});
      }
    for (int i = 0; i + 1 < k; ++i)
      for (int j = 0; j + 1 < k; ++j) {
        const int a = i * k + j, b = a + 1, c = a + k, d = c + 1;
        t.insert(t.end(), {a, c, b, b, c, d});
      }
    n = v.size() / 3;
  }
};

TEST(DeformationTransfer, IdentityGradientsReturnTheInputAndTheSolveMatchesEigen) {
  const Grid g;
  const SkinGeometry geo = SkinGeometry::measure(g.v.data(), g.n, g.t);
  const DeformationTransfer dt(geo, g.n, g.t, 1e-3);
  std::vector<float> zero(kRhsStride * g.n, 0.0f), out(3 * g.n);
  std::vector<double> work(dt.work_size());
  const float* zero_parts[1] = {zero.data()};
  dt.solve(zero_parts, 1, g.v.data(), work.data(), out.data());
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_FLOAT_EQ(out[i], g.v[i]);
  // K x = r against a dense solve of the same matrix.
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(g.n), static_cast<Eigen::Index>(g.n));
  double mean_mass = 0;
  for (double m : geo.vertex_mass) mean_mass += m / static_cast<double>(g.n);
  for (std::size_t f = 0; f < g.t.size() / 3; ++f) {
    const int i = g.t[3 * f], j = g.t[3 * f + 1], k = g.t[3 * f + 2];
    const double c00 = geo.metric[3 * f], c01 = geo.metric[3 * f + 1], c11 = geo.metric[3 * f + 2];
    K(j, j) += c00; K(k, k) += c11; K(j, k) += c01; K(k, j) += c01;
    K(i, j) -= c00 + c01; K(j, i) -= c00 + c01; K(i, k) -= c01 + c11; K(k, i) -= c01 + c11;
    K(i, i) += c00 + 2 * c01 + c11;
  }
  for (std::size_t v = 0; v < g.n; ++v) K(static_cast<Eigen::Index>(v), static_cast<Eigen::Index>(v)) += 1e-3 / mean_mass * geo.vertex_mass[v];
  std::mt19937 rng(3);
  std::normal_distribution<float> nd;
  std::vector<float> r(kRhsStride * g.n), r2(kRhsStride * g.n);  // x, y, z and an unread lane
  for (auto& x : r) x = nd(rng);
  for (std::size_t i = 0; i < r.size(); ++i) r2[i] = 0.25f * r[i];
  const float* parts[2] = {r.data(), r2.data()};
  dt.solve(parts, 2, zero.data(), work.data(), out.data());  // r + r/4 = 1.25 r
  Eigen::MatrixXd rhs(static_cast<Eigen::Index>(g.n), 3);
  for (std::size_t v = 0; v < g.n; ++v)
    for (int c = 0; c < 3; ++c) rhs(static_cast<Eigen::Index>(v), c) = 1.25 * r[kRhsStride * v + static_cast<std::size_t>(c)];
  const Eigen::MatrixXd x = K.ldlt().solve(rhs);
  for (std::size_t v = 0; v < g.n; ++v)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[3 * v + c], x(static_cast<Eigen::Index>(v), c), 1e-5 * x.cwiseAbs().maxCoeff());
}

// A neutral vertex far outside any head is named as such, not reported as a triangle of area 0;
// a truly degenerate triangle's message gives its area's magnitude.
TEST(DeformationTransfer, AWildNeutralVertexIsNamed) {
  const Grid g;
  std::vector<float> v = g.v;
  v[3 * 5 + 1] = 1e30f;
  try {
    SkinGeometry::measure(v.data(), g.n, g.t);
    ADD_FAILURE() << "accepted a vertex at 1e30 m";
  } catch (const softdeca::Error& e) {
    EXPECT_EQ(std::string(e.what()), "vertex 5 of the neutral is not within 100 m of the origin (coordinate 1e+30)");
  }
  std::vector<float> flat = g.v;
  const auto at = [&](int corner, int c) -> float& { return flat[3 * static_cast<std::size_t>(g.t[static_cast<std::size_t>(corner)]) + static_cast<std::size_t>(c)]; };
  for (int c = 0; c < 3; ++c) at(1, c) = at(2, c) = at(0, c);
  at(1, 0) += 1e-6f;  // a triangle of 5e-13 m^2
  at(2, 1) += 1e-6f;
  try {
    SkinGeometry::measure(flat.data(), g.n, g.t);
    ADD_FAILURE() << "accepted a degenerate triangle";
  } catch (const softdeca::Error& e) {
    EXPECT_NE(std::string(e.what()).find("is degenerate (area "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("e-13 m^2"), std::string::npos) << e.what();
  }
}

TEST(DeformationTransfer, KernelMatchesTheDirectRightHandSide) {
  Grid g;  // its faces shuffled, which the transfer's own face order (the tensor's) must undo
  std::vector<std::int32_t> order(g.t.size() / 3), shuffled(g.t.size());
  std::iota(order.begin(), order.end(), 0), std::shuffle(order.begin(), order.end(), std::mt19937(11));
  for (std::size_t f = 0; f < order.size(); ++f) std::copy_n(g.t.begin() + 3 * order[f], 3, shuffled.begin() + 3 * f);
  g.t = shuffled;
  const SkinGeometry geo = SkinGeometry::measure(g.v.data(), g.n, g.t);
  const DeformationTransfer dt(geo, g.n, g.t, 1e-3);
  const std::size_t nf = g.t.size() / 3;
  const int K = 32;
  std::mt19937 rng(7);
  std::normal_distribution<float> nd;
  std::vector<float> L(nf * K * 9), z(K), skin(g.v);
  for (auto& x : L) x = 0.05f * nd(rng);
  for (auto& x : z) x = nd(rng);
  for (auto& x : skin) x += 0.003f * nd(rng);
  // Direct: r = sum_f D_f a_f W_f ((G_f - I) E_f)^T with G_f - I = z . L_f.
  std::vector<double> want(3 * g.n, 0.0);
  for (std::size_t f = 0; f < nf; ++f) {
    double d[9] = {};
    for (int k = 0; k < K; ++k)
      for (int c = 0; c < 9; ++c) d[c] += double(z[k]) * L[(f * K + k) * 9 + c];
    const int i = g.t[3 * f], j = g.t[3 * f + 1], kk = g.t[3 * f + 2];
    for (int r = 0; r < 3; ++r) {
      double p0 = 0, p1 = 0;
      for (int c = 0; c < 3; ++c) {
        p0 += d[3 * r + c] * (skin[3 * j + c] - skin[3 * i + c]);
        p1 += d[3 * r + c] * (skin[3 * kk + c] - skin[3 * i + c]);
      }
      const double col0 = p0 * geo.metric[3 * f] + p1 * geo.metric[3 * f + 1], col1 = p0 * geo.metric[3 * f + 1] + p1 * geo.metric[3 * f + 2];
      want[3 * j + r] += col0, want[3 * kk + r] += col1, want[3 * i + r] -= col0 + col1;
    }
  }
  double scale = 0;
  for (double w : want) scale = std::max(scale, std::fabs(w));
  for (const Precision p : {Precision::Float, Precision::Half, Precision::Int8}) {
    const HyperTensor tensor(L.data(), nf, K, 9, p, dt.face_order().data());  // in the faces' order
    for (const Kernel kernel : {Kernel::Best, Kernel::Portable, Kernel::Avx2, Kernel::Avx512Vnni, Kernel::Neon}) {
      if (!kernel_available(kernel)) continue;
      std::vector<float> got(kRhsStride * g.n, 0.0f);
      const std::size_t half = tensor.blocks() / 2;  // two ranges, as two threads would do
      dg_rhs(tensor, dt.faces(), z.data(), skin.data(), 0, half, got.data(), kernel);
      dg_rhs(tensor, dt.faces(), z.data(), skin.data(), half, tensor.blocks(), got.data(), kernel);
      const double tol = p == Precision::Float ? 1e-5 : p == Precision::Half ? 2e-3 : 2e-2;
      for (std::size_t i = 0; i < want.size(); ++i)
        EXPECT_NEAR(got[kRhsStride * (i / 3) + i % 3], want[i], tol * scale) << "precision " << int(p) << " kernel " << int(kernel);
    }
    // Stored values read back within the precision's step.
    for (std::size_t f = 0; f < nf; f += 5)
      for (int k = 0; k < K; k += 3)
        EXPECT_NEAR(tensor.at(f, k, 4), L[(std::size_t(dt.face_order()[f]) * K + k) * 9 + 4], p == Precision::Float ? 0.0 : 0.0025);
  }
}

TEST(HyperTensor, VertexOffsetsMatchTheDirectProduct) {
  const std::size_t n = 29;  // not a multiple of the block size
  for (const int K : {32, 7}) {  // 7: int8 pads the latents to pairs
    std::mt19937 rng(5);
    std::normal_distribution<float> nd;
    std::vector<float> L(n * K * 3), z(K), base(3 * n), add(3 * n);
    for (auto& x : L) x = 0.001f * nd(rng);
    for (auto& x : z) x = nd(rng);
    for (auto& x : base) x = nd(rng);
    for (auto& x : add) x = 0.001f * nd(rng);
    for (const auto& [p, kernel] : std::vector<std::pair<Precision, Kernel>>{
             {Precision::Float, Kernel::Avx2}, {Precision::Float, Kernel::Portable}, {Precision::Half, Kernel::Avx2},
             {Precision::Half, Kernel::Portable}, {Precision::Int8, Kernel::Avx2}, {Precision::Int8, Kernel::Avx512Vnni},
             {Precision::Int8, Kernel::Portable}, {Precision::Float, Kernel::Neon}, {Precision::Half, Kernel::Neon},
             {Precision::Int8, Kernel::Neon}}) {
      if (!kernel_available(kernel)) continue;
      std::vector<float> out(3 * n + 3, -7.0f);
      const HyperTensor t(L.data(), n, K, 3, p);
      vertex_offsets(t, z.data(), base.data(), add.data(), 0, t.blocks(), out.data(), kernel);
      // In place (out is base), and without a base (the offsets alone): the same sums.
      std::vector<float> in_place(base), alone(3 * n);
      vertex_offsets(t, z.data(), in_place.data(), add.data(), 0, t.blocks(), in_place.data(), kernel);
      vertex_offsets(t, z.data(), nullptr, add.data(), 0, t.blocks(), alone.data(), kernel);
      EXPECT_EQ(in_place, std::vector<float>(out.begin(), out.end() - 3));
      for (std::size_t i = 0; i < 3 * n; ++i) EXPECT_NEAR(alone[i] + base[i], out[i], 1e-6);
      // Tolerance: float rounding; half's 2^-11 and int8's 1/254 of each term, summed.
      const double step = p == Precision::Float ? 1e-6 : p == Precision::Half ? 1e-3 : 8e-3;
      for (std::size_t v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c) {
          double want = base[3 * v + c] + add[3 * v + c], size = 0;
          for (int k = 0; k < K; ++k) {
            want += double(z[k]) * L[(v * K + k) * 3 + c];
            size += std::fabs(double(z[k])) * 0.004;  // |L| < 4 sigma
          }
          EXPECT_NEAR(out[3 * v + c], want, 1e-6 + step * size)
              << "K " << K << " precision " << static_cast<int>(p) << " kernel " << static_cast<int>(kernel);
          EXPECT_NEAR(t.at(v, K - 1, c), L[(v * K + K - 1) * 3 + c], p == Precision::Float ? 0.0 : 0.004 / 100);
        }
      for (int c = 0; c < 3; ++c) EXPECT_EQ(out[3 * n + c], -7.0f) << "wrote past the last vertex";
      std::vector<double> peak(K, 0.0);  // each latent's largest stored magnitude bounds a frame's sums
      for (std::size_t e = 0; e < n * K * 3; ++e)
        peak[e / 3 % K] = std::max(peak[e / 3 % K], std::fabs(double(t.at(e / 3 / K, int(e / 3 % K), int(e % 3)))));
      for (int k = 0; k < K; ++k) EXPECT_NEAR(t.peak(k), peak[k], 1e-6 * peak[k]) << "latent " << k;
    }
  }
}

// A large term that cancels against another (collinear columns of a fitted table) must not
// set the rounding of the small ones: every kernel matches the stored values' exact contraction
// to float rounding of the large term, on every family (tests/cpu/run-as.sh).
TEST(HyperTensor, Int8KernelsKeepSmallTermsBesideALargeOne) {
  const std::size_t n = 24;
  const int K = 32;
  std::mt19937 rng(11);
  std::normal_distribution<float> nd;
  std::vector<float> L(n * K * 3), z(K), base(3 * n, 0.0f);
  for (std::size_t v = 0; v < n; ++v)
    for (int c = 0; c < 3; ++c) {
      const float big = nd(rng);  // latents 0 and 1: +big and -big with z = 1 each: they cancel
      for (int k = 0; k < K; ++k) L[(v * K + k) * 3 + c] = k == 0 ? big : k == 1 ? -big : 1e-3f * nd(rng);
    }
  for (int k = 0; k < K; ++k) z[k] = k < 2 ? 1.0f : nd(rng);
  const HyperTensor t(L.data(), n, K, 3, Precision::Int8);
  for (const Kernel kernel : {Kernel::Portable, Kernel::Avx2, Kernel::Avx512Vnni, Kernel::Neon}) {
    if (!kernel_available(kernel)) continue;
    std::vector<float> out(3 * n);
    vertex_offsets(t, z.data(), base.data(), 0, t.blocks(), out.data(), kernel);
    double worst = 0;
    for (std::size_t v = 0; v < n; ++v)
      for (int c = 0; c < 3; ++c) {
        double want = 0;  // the stored (int8) values, contracted exactly
        for (int k = 0; k < K; ++k) want += double(z[k]) * t.at(v, k, c);
        worst = std::max(worst, std::fabs(out[3 * v + c] - want));
      }
    // float rounding of the unit-sized terms (2^-24 each, a few of them); the small terms are
    // ~1e-3 each, so one step of 1/32767 of the large term (3e-5) per term would fail this.
    EXPECT_LT(worst, 2e-6) << "kernel " << static_cast<int>(kernel);
  }
}

TEST(SparseLdlt, RefusesAMatrixThatIsNotPositiveDefinite) {
  Eigen::SparseMatrix<double> K(3, 3);
  K.insert(0, 0) = 1;
  K.insert(1, 1) = -1;
  K.insert(2, 2) = 1;
  EXPECT_THROW(SparseLdlt{K}, softdeca::Error);
}

TEST(Blendshapes, RunsReproduceTheDenseBlendInEveryPart) {
  const std::size_t n = 200, shapes = 52;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<float> deltas(shapes * n * 3, 0.0f), neutral(3 * n), w(shapes);
  for (std::size_t s = 0; s < shapes; ++s)
    for (std::size_t v = 0; v < n; ++v)
      if ((v * 7 + s * 13) % 5 < 2 || (v > 50 && v < 60))  // scattered vertices, gaps, and one run
        for (int c = 0; c < 3; ++c) deltas[(s * n + v) * 3 + c] = u(rng);
  for (auto& x : neutral) x = u(rng);
  for (std::size_t s = 0; s < shapes; ++s) w[s] = s % 4 == 0 ? 0.0f : (u(rng) + 1) / 2;
  for (const std::size_t parts : {1u, 2u, 3u}) {
    const Blendshapes b(deltas.data(), shapes, n, parts);
    std::vector<float> out(3 * n, 0.0f);
    for (std::size_t p = 0; p < parts; ++p) b.blend(w.data(), neutral.data(), out.data(), p);
    double moved = 0;  // the most the shapes move a coordinate, which reach() bounds
    for (std::size_t v = 0; v < n; ++v)
      for (int c = 0; c < 3; ++c) {
        double want = neutral[3 * v + c];
        for (std::size_t s = 0; s < shapes; ++s) want += double(w[s]) * deltas[(s * n + v) * 3 + c];
        EXPECT_NEAR(out[3 * v + c], want, 1e-5) << parts;
        moved = std::max(moved, std::fabs(want - neutral[3 * v + c]));
      }
    EXPECT_GE(b.reach(w.data()), moved);
  }
  deltas[(1 * n + 55) * 3] = std::numeric_limits<float>::infinity();  // a moved shape's: no bound
  EXPECT_TRUE(std::isinf(Blendshapes(deltas.data(), shapes, n, 1).reach(w.data())));
}

TEST(Normals, AreUnitAreaWeightedAndZeroWhereUndefined) {
  // Two triangles of a unit square in the xy plane, plus an isolated vertex.
  const std::vector<float> v = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 5, 5, 5};
  const std::vector<int32_t> t = {0, 1, 2, 0, 2, 3};
  Normals normals(t, 5);
  std::vector<float> out(15, -1.0f);
  for (std::size_t p = 0; p < 2; ++p) normals.faces(v.data(), p, 2);
  for (std::size_t p = 0; p < 2; ++p) normals.vertices(out.data(), p, 2);
  for (int i = 0; i < 4; ++i) {
    EXPECT_FLOAT_EQ(out[3 * i + 2], 1.0f);
    EXPECT_FLOAT_EQ(out[3 * i], 0.0f);
  }
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[12 + c], 0.0f);
}

TEST(Rigid, RecoversAKnownSimilarity) {
  std::mt19937 rng(2);
  std::normal_distribution<double> nd;
  std::vector<double> src(60), dst(60);
  for (auto& x : src) x = nd(rng);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.1, -0.2, 0.3);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d p = 1.3 * R * Eigen::Vector3d(src[3 * i], src[3 * i + 1], src[3 * i + 2]) + t;
    for (int c = 0; c < 3; ++c) dst[3 * i + c] = p[c];
  }
  const Similarity s = fit_similarity(src.data(), dst.data(), 20, true);
  EXPECT_NEAR(s.scale, 1.3, 1e-9);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(s.translation[i], t[i], 1e-9);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(s.rotation[3 * i + j], R(i, j), 1e-9);
  }
  const Similarity k = fit_similarity(src.data(), dst.data(), 20, false);
  EXPECT_EQ(k.scale, 1.0);
  // A mirror image still gets a proper rotation.
  for (int i = 0; i < 20; ++i) dst[3 * i] = -src[3 * i], dst[3 * i + 1] = src[3 * i + 1], dst[3 * i + 2] = src[3 * i + 2];
  const Similarity m = fit_similarity(src.data(), dst.data(), 20, false);
  Eigen::Matrix3d r;
  for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = m.rotation[i];
  EXPECT_NEAR(r.determinant(), 1.0, 1e-9);
}

TEST(Dynamics, StartAtRestAndFollowTheRecursion) {
  const std::size_t n = 3;
  DynamicsCoefficients c;
  c.alpha.resize(n);
  c.beta.resize(n);
  c.gamma.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    c.gamma[v] = 0.5f;
    c.beta[v] = 0.2f;
    c.alpha[v] = 0.5f * (1.0f - 0.5f + 0.2f);
  }
  DynamicsState s(n);
  std::vector<float> y0(9, 1.0f), y1(9, 2.0f);
  s.step(c, 0, y0.data(), 0, n);
  EXPECT_EQ(std::vector<float>(s.next(), s.next() + 9), y0);
  s.commit(0);
  s.step(c, 0, y1.data(), 0, n);  // 0.5*2 + 2*0.35*1 - 0.2*1 = 1.5
  EXPECT_FLOAT_EQ(s.next()[4], 1.5f);
  s.commit(0);
  s.step(c, 0, y1.data(), 0, n);  // 0.5*2 + 0.7*1.5 - 0.2*1 = 1.85
  EXPECT_FLOAT_EQ(s.next()[0], 1.85f);
  // Another model starts at rest again.
  s.step(c, 1, y1.data(), 0, n);
  EXPECT_FLOAT_EQ(s.next()[0], 2.0f);
}

TEST(Worker, RunsEveryPartOnce) {
  for (const std::size_t threads : {1u, 2u, 4u}) {
    Worker w(threads);
    for (int round = 0; round < 200; ++round) {
      std::vector<std::atomic<int>> hits(w.parts());
      auto f = [&](std::size_t part, std::size_t parts) {
        EXPECT_EQ(parts, w.parts());
        hits[part].fetch_add(1);
      };
      w.run(f);
      for (auto& h : hits) ASSERT_EQ(h.load(), 1);
    }
  }
}

TEST(Json, ParsesTheSubsetManifestsUse) {
  const Json j = Json::parse(R"({"a": [1, -2.5e3, true, false, null], "s": "x\"y\\n\u00e9", "o": {}})");
  ASSERT_EQ(j.at("a", "").array("").size(), 5u);
  EXPECT_EQ(j.at("a", "").array("")[1].number(""), -2500.0);
  EXPECT_TRUE(j.at("a", "").array("")[2].boolean(""));
  EXPECT_TRUE(j.at("a", "").array("")[4].is_null());
  EXPECT_EQ(j.at("s", "").string(""), "x\"y\\n\xc3\xa9");
  EXPECT_TRUE(j.at("o", "").is_object());
  for (const char* bad : {"", "{", "[1,]", "{\"a\" 1}", "\"unterminated", "[1] x", "nul", "{\"a\": 1e999}"})
    EXPECT_THROW(Json::parse(bad), softdeca::Error) << bad;
  EXPECT_THROW(j.at("missing", "doc"), softdeca::Error);
  EXPECT_THROW(j.at("s", "doc").number("s"), softdeca::Error);
  EXPECT_THROW(Json::parse("[1.5]").array("")[0].integer("x"), softdeca::Error);
  std::string deep(200, '[');
  EXPECT_THROW(Json::parse(deep), softdeca::Error);
}

TEST(Json, BoundsItsNestingAndItsValues) {
  // Every value counts: the array, its members, an object's member values.
  softdeca::bundle::JsonLimits limits;
  limits.max_values = 4;
  EXPECT_NO_THROW(Json::parse("[1, 2, 3]", limits));
  EXPECT_THROW(Json::parse("[1, 2, 3, 4]", limits), softdeca::Error);
  EXPECT_THROW(Json::parse(R"({"a": [1, 2], "b": 3})", limits), softdeca::Error);
  limits = {};
  limits.max_depth = 3;  // the document is at depth 0, the 1 in [[[1]]] at 3
  EXPECT_NO_THROW(Json::parse("[[[1]]]", limits));
  try {
    Json::parse("[[[[1]]]]", limits);
    ADD_FAILURE() << "a value 4 deep was read";
  } catch (const softdeca::Error& e) {
    EXPECT_NE(std::string(e.what()).find("nesting deeper than 3"), std::string::npos) << e.what();
  }
  const Json j = Json::parse(R"({"k": 1, "k": 2})");
  ASSERT_EQ(j.members("").size(), 2u);  // in file order, repeats kept
  EXPECT_EQ(j.members("")[1].second.number(""), 2);
  EXPECT_STREQ(j.kind(), "an object");
}

// A ustar member header (name, size, checksum) followed by its data padded to 512 bytes.
std::vector<uint8_t> tar_member(const std::string& name, const std::string& data) {
  std::vector<uint8_t> h(512, 0);
  std::memcpy(h.data(), name.data(), name.size());
  std::snprintf(reinterpret_cast<char*>(h.data() + 100), 8, "%07o", 0644);
  std::snprintf(reinterpret_cast<char*>(h.data() + 124), 12, "%011zo", data.size());
  h[156] = '0';
  std::memcpy(h.data() + 257, "ustar", 6);
  std::memset(h.data() + 148, ' ', 8);
  unsigned sum = 0;
  for (uint8_t b : h) sum += b;
  std::snprintf(reinterpret_cast<char*>(h.data() + 148), 8, "%06o", sum);
  std::vector<uint8_t> out(512 + (data.size() + 511) / 512 * 512, 0);
  std::memcpy(out.data(), h.data(), 512);
  if (!data.empty()) std::memcpy(out.data() + 512, data.data(), data.size());
  return out;
}

TEST(BundleFiles, ReadsTarArchivesAndRejectsDamage) {
  auto tar = tar_member("top/manifest.json", "{}");
  const auto second = tar_member("top/x.bin", std::string("\x01\x02\x03", 3));
  tar.insert(tar.end(), second.begin(), second.end());
  tar.resize(tar.size() + 1024, 0);
  const BundleFiles files = BundleFiles::from_tar(tar.data(), tar.size());
  EXPECT_EQ(files.get("manifest.json").size(), 2u);  // the top folder is stripped
  EXPECT_EQ(files.get("x.bin").size(), 3u);
  EXPECT_THROW(files.get("missing"), softdeca::Error);
  EXPECT_THROW(files.get("../etc/passwd"), softdeca::Error);
  auto bad = tar;
  bad[130] = '9';  // not octal
  EXPECT_THROW(BundleFiles::from_tar(bad.data(), bad.size()), softdeca::Error);
  EXPECT_THROW(BundleFiles::from_tar(tar.data(), 700), softdeca::Error);
  std::vector<uint8_t> zeros(1024, 0);
  EXPECT_THROW(BundleFiles::from_tar(zeros.data(), zeros.size()), softdeca::Error);
}

// Prepare runs the networks once per distinct parameter set, so equal states must compare equal
// however they were reached, and differ in a kind, a global value or a map's entry.
TEST(ParameterState, ComparesKindsValuesAndMaps) {
  Manifest m;
  m.skin_vertices = 3;
  for (const char* name : {"a", "b"}) {
    softdeca::ParameterSpec p;
    p.name = name;
    p.default_value = 0.5;
    p.maximum = 1;
    p.localisable = true;
    m.parameters.push_back(p);
  }
  const std::vector<std::int32_t> triangles = {0, 1, 2};
  const std::vector<double> area = {1.0};
  ParameterState x(m, triangles, area), y(m, triangles, area);
  EXPECT_TRUE(x == y);
  x.set_global(1, 0.25);
  EXPECT_FALSE(x == y);
  EXPECT_TRUE(x.only({1}) == x);  // every change is in the listed parameters
  EXPECT_TRUE(x.only({0}).at_defaults());
  y.set_global(1, 0.25);
  EXPECT_TRUE(x == y);
  const float map[] = {0.25f, 0.25f, 0.25f};
  y.set_vertices(1, map, 3);  // the same values as a map: another input kind, another state
  EXPECT_FALSE(x == y);
  x.set_vertices(1, map, 3);
  EXPECT_TRUE(x == y);
  const float other[] = {0.25f, 0.5f, 0.25f};
  x.set_vertices(1, other, 3);
  EXPECT_FALSE(x == y);
}
}  // namespace
