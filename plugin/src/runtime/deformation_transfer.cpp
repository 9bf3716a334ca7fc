#include "runtime/deformation_transfer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.h"

namespace softdeca::runtime {

namespace {
constexpr double kMinFaceArea = 1e-12;  // m^2, as dt.py
constexpr double kMaxVertexMetres = 100;  // a neutral face mesh lies within this of its origin

// Numbers in messages with their magnitude (std::to_string would print 1e-20 as 0.000000).
std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

Eigen::SparseMatrix<double> assemble(const SkinGeometry& g, std::size_t n, const std::vector<std::int32_t>& t,
                                     double regularisation) {
  std::vector<Eigen::Triplet<double>> entries;
  const std::size_t nf = t.size() / 3;
  entries.reserve(nf * 9 + n);
  for (std::size_t f = 0; f < nf; ++f) {
    const int i = t[3 * f], j = t[3 * f + 1], k = t[3 * f + 2];
    const double c00 = g.metric[3 * f], c01 = g.metric[3 * f + 1], c11 = g.metric[3 * f + 2];
    entries.emplace_back(j, j, c00);
    entries.emplace_back(k, k, c11);
    entries.emplace_back(j, k, c01);
    entries.emplace_back(k, j, c01);
    entries.emplace_back(i, j, -c00 - c01);
    entries.emplace_back(j, i, -c00 - c01);
    entries.emplace_back(i, k, -c01 - c11);
    entries.emplace_back(k, i, -c01 - c11);
    entries.emplace_back(i, i, c00 + 2 * c01 + c11);
  }
  double mean_mass = 0;
  for (const double m : g.vertex_mass) mean_mass += m;
  mean_mass /= static_cast<double>(n);
  const double mu = regularisation / mean_mass;
  for (std::size_t v = 0; v < n; ++v) entries.emplace_back(static_cast<int>(v), static_cast<int>(v), mu * g.vertex_mass[v]);
  Eigen::SparseMatrix<double> K(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  K.setFromTriplets(entries.begin(), entries.end());
  return K;
}

// The faces by their smallest corner: the right-hand side pass reads and adds to the corners of
// 8 faces at a time, and faces that share vertices then follow each other. In the template's
// own order a vertex's faces lay three quarters of the list apart (median), and the pass took
// 0.65 ms where it takes 0.50 in this order (docs/performance-notes.md).
std::vector<std::int32_t> local_order(const std::vector<std::int32_t>& t) {
  std::vector<std::int32_t> order(t.size() / 3);
  for (std::size_t f = 0; f < order.size(); ++f) order[f] = static_cast<std::int32_t>(f);
  const auto first = [&](std::int32_t f) {
    const std::size_t b = 3 * static_cast<std::size_t>(f);
    return std::min({t[b], t[b + 1], t[b + 2]});
  };
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) { return first(a) < first(b); });
  return order;
}

kernels::FaceBlocks face_blocks(const SkinGeometry& g, const std::vector<std::int32_t>& t,
                                const std::vector<std::int32_t>& order) {
  kernels::FaceBlocks fb;
  const std::size_t nf = order.size();
  fb.blocks = (nf + kernels::kLanes - 1) / kernels::kLanes;
  fb.corners.resize(fb.blocks * 3 * kernels::kLanes);
  fb.coeff.resize(fb.blocks * 3 * kernels::kLanes);
  for (std::size_t e = 0; e < nf; ++e) {
    const std::size_t base = (e / kernels::kLanes) * 3 * kernels::kLanes, lane = e % kernels::kLanes,
                      f = static_cast<std::size_t>(order[e]);
    for (std::size_t c = 0; c < 3; ++c) {
      fb.corners[base + c * kernels::kLanes + lane] = t[3 * f + c];
      fb.coeff[base + c * kernels::kLanes + lane] = static_cast<float>(g.metric[3 * f + c]);
    }
  }
  return fb;
}
}  // namespace

SkinGeometry SkinGeometry::measure(const float* skin, std::size_t n, const std::vector<std::int32_t>& t) {
  SkinGeometry g;
  const std::size_t nf = t.size() / 3;
  g.face_area.resize(nf);
  g.metric.resize(3 * nf);
  g.vertex_mass.assign(n, 0.0);
  // A vertex far outside any head (1e30) would otherwise surface as a triangle of "area 0".
  for (std::size_t i = 0; i < 3 * n; ++i)
    expect(std::isfinite(skin[i]) && std::fabs(skin[i]) <= kMaxVertexMetres, [&] {
      return "vertex " + std::to_string(i / 3) + " of the neutral is not within " + format_number(kMaxVertexMetres) +
             " m of the origin (coordinate " + format_number(skin[i]) + ")";
    });
  for (std::size_t f = 0; f < nf; ++f) {
    const float* a = skin + 3 * static_cast<std::size_t>(t[3 * f]);
    const float* b = skin + 3 * static_cast<std::size_t>(t[3 * f + 1]);
    const float* c = skin + 3 * static_cast<std::size_t>(t[3 * f + 2]);
    double e1[3], e2[3];
    for (int d = 0; d < 3; ++d) {
      e1[d] = static_cast<double>(b[d]) - a[d];
      e2[d] = static_cast<double>(c[d]) - a[d];
    }
    const double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
    const double area = 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
    expect(area >= kMinFaceArea, [&] {
      return "skin triangle " + std::to_string(f) + " of the neutral is degenerate (area " + format_number(area) + " m^2)";
    });
    const double g00 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    const double g01 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    const double g11 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    const double det = g00 * g11 - g01 * g01;
    g.face_area[f] = area;
    g.metric[3 * f] = g11 / det * area;
    g.metric[3 * f + 1] = -g01 / det * area;
    g.metric[3 * f + 2] = g00 / det * area;
    for (int c2 = 0; c2 < 3; ++c2) g.vertex_mass[static_cast<std::size_t>(t[3 * f + c2])] += area / 3.0;
  }
  return g;
}

DeformationTransfer::DeformationTransfer(const SkinGeometry& g, std::size_t n, const std::vector<std::int32_t>& t,
                                         double regularisation, std::size_t parts)
    : face_order_(local_order(t)), faces_(face_blocks(g, t, face_order_)), ldlt_(assemble(g, n, t, regularisation), parts) {}

void DeformationTransfer::solve(const float* const* r, std::size_t count, const float* skin, double* work, float* out) const {
  ldlt_.solve(r, count, work, out);
  const std::size_t n = 3 * ldlt_.size();
  for (std::size_t i = 0; i < n; ++i) out[i] += skin[i];
}

}  // namespace softdeca::runtime
