#include "fit/shape_guides.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace softdeca::fit {
namespace {

constexpr double kRadius = 0.02;      // metres a guide's avatar vertex may lie from the template vertex
constexpr double kCell = 0.01;        // the search grid
constexpr double kPlaceWeight = 0.5;  // distance's share of the cost, at kRadius
constexpr std::size_t kMaxGuides = 800;

// The 95th percentile of a shape's motion over the vertices it moves: its typical size.
double typical(const float* d, const std::vector<std::size_t>& vertices, const Eigen::Matrix3d& lin) {
  std::vector<double> m;
  m.reserve(vertices.size());
  for (const std::size_t v : vertices) {
    const double l = (lin * Eigen::Vector3d(d[3 * v], d[3 * v + 1], d[3 * v + 2])).norm();
    if (l > 0) m.push_back(l);
  }
  if (m.empty()) return 0;
  const std::size_t k = m.size() * 95 / 100;
  std::nth_element(m.begin(), m.begin() + static_cast<std::ptrdiff_t>(k), m.end());
  return m[k];
}

struct CellKey {
  long x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    return static_cast<std::size_t>(k.x * 73856093L ^ k.y * 19349663L ^ k.z * 83492791L);
  }
};
CellKey cell_of(const Eigen::Vector3d& p) {
  return {static_cast<long>(std::floor(p[0] / kCell)), static_cast<long>(std::floor(p[1] / kCell)),
          static_cast<long>(std::floor(p[2] / kCell))};
}

}  // namespace

std::vector<Guide> shape_guides(const ShapeInputs& in, const Points& tskin, const Points& avatar, const Eigen::Matrix3d& lin) {
  const std::size_t vs = in.t.skin_vertices, n = in.a.vertex_count;
  std::vector<std::size_t> tface, aface;
  for (std::size_t v = 0; v < vs; ++v)
    if (in.template_face[v]) tface.push_back(v);
  for (std::size_t v = 0; v < n; ++v)
    if (in.avatar_face[v] && in.avatar_skin[v]) aface.push_back(v);
  // The shapes both move, each with its typical size on either mesh.
  struct Common {
    const float* t;
    const float* a;
    double st, sa;
  };
  std::vector<Common> common;
  for (std::size_t k = 0; k < kShapes; ++k) {
    if (!in.t.moves[k] || !in.a.deltas[k]) continue;
    const float* td = in.t.shapes + k * vs * 3;
    const double st = typical(td, tface, Eigen::Matrix3d::Identity()), sa = typical(in.a.deltas[k], aface, lin);
    if (st > 0 && sa > 0) common.push_back({td, in.a.deltas[k], st, sa});
  }
  if (common.size() < 3 || tface.empty() || aface.empty()) return {};
  const std::size_t dims = 3 * common.size();
  const auto descriptor = [&](bool tmpl, std::size_t v, double* out) {
    for (std::size_t c = 0; c < common.size(); ++c) {
      const float* d = tmpl ? common[c].t : common[c].a;
      Eigen::Vector3d m(d[3 * v], d[3 * v + 1], d[3 * v + 2]);
      if (!tmpl) m = lin * m;
      m /= tmpl ? common[c].st : common[c].sa;
      for (int i = 0; i < 3; ++i) out[3 * c + static_cast<std::size_t>(i)] = m[i];
    }
  };
  std::vector<double> fa(aface.size() * dims);
  for (std::size_t j = 0; j < aface.size(); ++j) descriptor(false, aface[j], fa.data() + j * dims);
  std::unordered_map<CellKey, std::vector<std::size_t>, CellHash> grid;
  for (std::size_t j = 0; j < aface.size(); ++j)
    grid[cell_of(avatar.row(static_cast<Eigen::Index>(aface[j])).transpose())].push_back(j);

  // Template vertices the shapes move most: their responses are distinctive.
  std::vector<double> ft(dims);
  std::vector<std::pair<double, std::size_t>> energy;
  for (const std::size_t v : tface) {
    descriptor(true, v, ft.data());
    double e = 0;
    for (const double x : ft) e += x * x;
    energy.emplace_back(e / static_cast<double>(common.size()), v);
  }
  std::sort(energy.begin(), energy.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  energy.resize(energy.size() / 2);
  const std::size_t stride = std::max<std::size_t>(1, energy.size() / kMaxGuides);
  std::vector<Guide> guides;
  const int reach = static_cast<int>(std::ceil(kRadius / kCell));
  for (std::size_t g = 0; g < energy.size(); g += stride) {
    const std::size_t v = energy[g].second;
    descriptor(true, v, ft.data());
    const Eigen::Vector3d x = tskin.row(static_cast<Eigen::Index>(v)).transpose();
    const CellKey c = cell_of(x);
    double best = std::numeric_limits<double>::infinity(), best_desc = 0;
    std::size_t best_j = 0;
    for (int dx = -reach; dx <= reach; ++dx)
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dz = -reach; dz <= reach; ++dz) {
          const auto it = grid.find({c.x + dx, c.y + dy, c.z + dz});
          if (it == grid.end()) continue;
          for (const std::size_t j : it->second) {
            const double d2 = (avatar.row(static_cast<Eigen::Index>(aface[j])).transpose() - x).squaredNorm();
            if (d2 > kRadius * kRadius) continue;
            double desc = 0;
            const double* f = fa.data() + j * dims;
            for (std::size_t i = 0; i < dims; ++i) desc += (f[i] - ft[i]) * (f[i] - ft[i]);
            desc /= static_cast<double>(common.size());
            const double cost = desc + kPlaceWeight * energy[g].first * d2 / (kRadius * kRadius);
            if (cost < best) best = cost, best_desc = desc, best_j = j;
          }
        }
    // A match must explain most of the vertex's response.
    if (std::isfinite(best) && best_desc < 0.25 * energy[g].first)
      guides.push_back({static_cast<std::int32_t>(v), avatar.row(static_cast<Eigen::Index>(aface[best_j])).transpose(), 1.0});
  }
  return guides;
}

}  // namespace softdeca::fit
