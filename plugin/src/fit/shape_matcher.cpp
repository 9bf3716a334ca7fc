#include "fit/shape_matcher.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

namespace softdeca::fit {

namespace {
constexpr double kMinNormalCos = 0.5;  // a closest point's triangle and the template vertex face alike (either winding)
constexpr double kMinEnergy = 0.005;   // mean squared response (of the largest, per shape) that describes a vertex
constexpr double kExplain = 0.1;       // a match must leave at most this share of the response unexplained
constexpr double kPrior = 0.05;        // the distance's weight in a match's cost, at the search radius
constexpr double kFineReach = 0.006;   // below this reach only closest points: the fine fit
constexpr double kThin = 8;            // candidates of a search: one per cell of its radius over this
constexpr std::int32_t kMaxFan = 64;   // triangles around the best candidate a match is placed on

struct CellKey {
  long x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    return static_cast<std::size_t>(k.x * 73856093L ^ k.y * 19349663L ^ k.z * 83492791L);
  }
};
CellKey cell_key(const Eigen::Vector3d& p, double cell) {
  const auto index = [&](double x) { return static_cast<long>(std::clamp(std::floor(x / cell), -1e15, 1e15)); };
  return {index(p[0]), index(p[1]), index(p[2])};
}
// A cell as one number, 21 bits an axis (cells 2 million apart share one: only thinning uses it).
std::uint64_t packed(const CellKey& k) {
  constexpr std::uint64_t kMask = (1u << 21) - 1;
  return (static_cast<std::uint64_t>(k.x) & kMask) | (static_cast<std::uint64_t>(k.y) & kMask) << 21 |
         (static_cast<std::uint64_t>(k.z) & kMask) << 42;
}

// Each shape's deltas over its largest (one row of `dims` per vertex), written row by row.
std::vector<float> avatar_descriptors(const std::vector<SharedShape>& shapes, std::size_t rows) {
  const std::size_t dims = 3 * shapes.size();
  std::vector<double> scale(shapes.size(), 0.0);
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    double peak = 0;
    for (std::size_t v = 0; v < rows; ++v) peak = std::max(peak, Eigen::Vector3f(shapes[s].avatar + 3 * v).cast<double>().squaredNorm());
    scale[s] = peak > 0 ? 1 / std::sqrt(peak) : 0;
  }
  std::vector<float> d(rows * dims);
  for (std::size_t v = 0; v < rows; ++v)
    for (std::size_t s = 0; s < shapes.size(); ++s)
      for (std::size_t c = 0; c < 3; ++c) d[v * dims + 3 * s + c] = static_cast<float>(shapes[s].avatar[3 * v + c] * scale[s]);
  return d;
}

std::vector<float> template_descriptors(const std::vector<SharedShape>& shapes, Eigen::Index rows) {
  const std::size_t dims = 3 * shapes.size();
  std::vector<float> d(static_cast<std::size_t>(rows) * dims, 0.0f);
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    const Points& delta = shapes[s].template_;
    const double peak = delta.rowwise().norm().maxCoeff();
    if (!(peak > 0)) continue;
    for (Eigen::Index v = 0; v < rows; ++v)
      for (int c = 0; c < 3; ++c)
        d[static_cast<std::size_t>(v) * dims + 3 * s + static_cast<std::size_t>(c)] = static_cast<float>(delta(v, c) / peak);
  }
  return d;
}

double dot(const float* a, const float* b, std::size_t n) {
  double s = 0;
  for (std::size_t i = 0; i < n; ++i) s += double(a[i]) * double(b[i]);
  return s;
}
}  // namespace

ShapeMatcher::ShapeMatcher(const Triangles& triangles, std::size_t vertices, std::vector<uint8_t> boundary_edges,
                           std::vector<uint8_t> boundary_vertex, std::vector<double> data_weight,
                           const std::vector<SharedShape>& shapes)
    : triangles_(triangles),
      boundary_edges_(std::move(boundary_edges)),
      boundary_vertex_(std::move(boundary_vertex)),
      data_weight_(std::move(data_weight)),
      dims_(3 * shapes.size()) {
  const Eigen::Index vs = static_cast<Eigen::Index>(data_weight_.size());
  avatar_desc_ = avatar_descriptors(shapes, vertices);
  template_desc_ = template_descriptors(shapes, vs);
  energy_.assign(static_cast<std::size_t>(vs), 0.0);
  if (dims_)
    for (Eigen::Index v = 0; v < vs; ++v) {
      const float* f = template_desc_.data() + static_cast<std::size_t>(v) * dims_;
      energy_[static_cast<std::size_t>(v)] = dot(f, f, dims_) / static_cast<double>(shapes.size());
    }
  // Each vertex's skin triangles, packed (a count, then the lists in vertex order).
  first_triangle_.assign(vertices + 1, 0);
  for (Eigen::Index f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++first_triangle_[static_cast<std::size_t>(triangles(f, k)) + 1];
  for (std::size_t v = 1; v < first_triangle_.size(); ++v) first_triangle_[v] += first_triangle_[v - 1];
  vertex_triangles_.resize(static_cast<std::size_t>(first_triangle_.back()));
  std::vector<std::int32_t> filled(first_triangle_.begin(), first_triangle_.end() - 1);
  for (Eigen::Index f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      vertex_triangles_[static_cast<std::size_t>(filled[static_cast<std::size_t>(triangles(f, k))]++)] = static_cast<std::int32_t>(f);
  described_.resize(static_cast<std::size_t>(vs));
}

void ShapeMatcher::place(const Points& avatar, const Eigen::Matrix3d& to_template, const geometry::Cutting& cutting) {
  // A placement after the first is a small rigid correction: the tree is kept, its boxes moved.
  if (surface_) surface_->move(avatar);
  else surface_ = std::make_unique<geometry::SurfaceQuery>(avatar, triangles_, cutting);
  // The template's responses in the avatar's axes: the placement's rotation undone.
  const Eigen::Matrix3d turn = to_template / std::cbrt(std::fabs(to_template.determinant()));
  template_turned_.resize(template_desc_.size());
  for (std::size_t i = 0; i < template_desc_.size(); i += 3) {
    const Eigen::Vector3d d = turn.transpose() * Eigen::Vector3f(template_desc_.data() + i).cast<double>();
    for (int c = 0; c < 3; ++c) template_turned_[i + static_cast<std::size_t>(c)] = static_cast<float>(d[c]);
  }
  // Once: a correction of the placement moves the candidates with the rest.
  if (candidates_.empty()) {
    std::vector<std::pair<std::uint64_t, std::int32_t>> cells;  // sorted: the first vertex of each cell kept
    for (Eigen::Index j = 0; j < avatar.rows(); ++j)
      if (first_triangle_[static_cast<std::size_t>(j) + 1] > first_triangle_[static_cast<std::size_t>(j)])
        cells.emplace_back(packed(cell_key(avatar.row(j).transpose(), kFineReach / kThin)), static_cast<std::int32_t>(j));
    std::sort(cells.begin(), cells.end());
    for (std::size_t i = 0; i < cells.size(); ++i)
      if (i == 0 || cells[i].first != cells[i - 1].first) candidates_.push_back(cells[i].second);
    std::sort(candidates_.begin(), candidates_.end());
  }
  searched_reach_ = 0;
}

std::size_t ShapeMatcher::described() const {
  return static_cast<std::size_t>(std::count_if(described_.begin(), described_.end(), [](const Match& m) { return m.weight > 0; }));
}

std::vector<Match> ShapeMatcher::shape_matches(const Points& skin, double radius) const {
  search(skin, radius);
  searched_reach_ = 0;  // the registration searches again from its own start
  return described_;
}

bool ShapeMatcher::on_boundary(const geometry::SurfacePoint& p) const {
  if (p.triangle < 0) return true;
  constexpr double kEdge = 1e-9;
  const auto t = static_cast<std::size_t>(p.triangle);
  int zero = -1, zeros = 0;
  for (int k = 0; k < 3; ++k)
    if (p.bary[k] <= kEdge) zero = k, ++zeros;
  if (zeros == 0) return false;
  if (zeros == 1) return (boundary_edges_[t] >> zero) & 1;
  for (int k = 0; k < 3; ++k)  // a corner
    if (p.bary[k] > kEdge) return boundary_vertex_[static_cast<std::size_t>(surface_->triangles()(p.triangle, k))] != 0;
  return true;
}

geometry::SurfacePoint ShapeMatcher::best_in_triangle(std::int32_t t, const float* target) const {
  const Triangles& f = surface_->triangles();
  const float* da = avatar_desc_.data() + static_cast<std::size_t>(f(t, 0)) * dims_;
  const float* db = avatar_desc_.data() + static_cast<std::size_t>(f(t, 1)) * dims_;
  const float* dc = avatar_desc_.data() + static_cast<std::size_t>(f(t, 2)) * dims_;
  // |A + u e1 + v e2|^2 over the triangle, A = da - target, e1 = db - da, e2 = dc - da.
  double aa = 0, ae1 = 0, ae2 = 0, e11 = 0, e12 = 0, e22 = 0;
  for (std::size_t i = 0; i < dims_; ++i) {
    const double a = double(da[i]) - target[i], e1 = double(db[i]) - da[i], e2 = double(dc[i]) - da[i];
    aa += a * a, ae1 += a * e1, ae2 += a * e2, e11 += e1 * e1, e12 += e1 * e2, e22 += e2 * e2;
  }
  const auto cost = [&](double u, double v) { return aa + 2 * u * ae1 + 2 * v * ae2 + u * u * e11 + 2 * u * v * e12 + v * v * e22; };
  const auto clamp01 = [](double x) { return std::min(1.0, std::max(0.0, x)); };
  double bu = 0, bv = 0, best = cost(0, 0);
  const auto consider = [&](double u, double v) {
    const double c = cost(u, v);
    if (c < best) best = c, bu = u, bv = v;
  };
  const double det = e11 * e22 - e12 * e12;
  if (det > 1e-18) {
    const double u = (-ae1 * e22 + ae2 * e12) / det, v = (-ae2 * e11 + ae1 * e12) / det;
    if (u >= 0 && v >= 0 && u + v <= 1) consider(u, v);
  }
  if (e11 > 0) consider(clamp01(-ae1 / e11), 0);
  if (e22 > 0) consider(0, clamp01(-ae2 / e22));
  const double gg = e11 - 2 * e12 + e22;
  if (gg > 0) {
    const double u = clamp01(-(ae1 - ae2 + e12 - e22) / gg);
    consider(u, 1 - u);
  }
  geometry::SurfacePoint p;
  p.triangle = t;
  p.bary = {1 - bu - bv, bu, bv};
  const Points& y = surface_->vertices();
  p.point = p.bary[0] * y.row(f(t, 0)).transpose() + p.bary[1] * y.row(f(t, 1)).transpose() + p.bary[2] * y.row(f(t, 2)).transpose();
  p.squared_distance = best;  // here: the response's squared difference
  return p;
}

void ShapeMatcher::search(const Points& skin, double radius) const {
  for (Match& m : described_) m.weight = 0;
  if (!dims_) return;
  const Points& y = surface_->vertices();
  // The candidates by cells of the radius, thinned to one per cell of a kThin-th of it: a
  // search looks at a bounded number of them however dense the mesh, and a match is then
  // placed on the triangles around the best.
  std::unordered_map<CellKey, std::vector<std::int32_t>, CellHash> grid;
  for (const std::int32_t j : candidates_) grid[cell_key(y.row(j).transpose(), radius)].push_back(j);
  std::unordered_set<std::uint64_t> taken;
  for (auto& [cell, members] : grid) {
    taken.clear();
    std::size_t kept = 0;
    for (const std::int32_t j : members)
      if (taken.insert(packed(cell_key(y.row(j).transpose(), radius / kThin))).second) members[kept++] = j;
    members.resize(kept);
  }
  const double n_shapes = static_cast<double>(dims_ / 3);
  for (Eigen::Index i = 0; i < skin.rows(); ++i) {
    const double e = energy_[static_cast<std::size_t>(i)];
    if (!(data_weight_[static_cast<std::size_t>(i)] > 0) || e < kMinEnergy) continue;
    const float* target = template_turned_.data() + static_cast<std::size_t>(i) * dims_;
    const Eigen::Vector3d x = skin.row(i).transpose();
    const CellKey c = cell_key(x, radius);
    double best = std::numeric_limits<double>::infinity();
    std::int32_t best_j = -1;
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find({c.x + dx, c.y + dy, c.z + dz});
          if (it == grid.end()) continue;
          for (const std::int32_t j : it->second) {
            const double d2 = (y.row(j).transpose() - x).squaredNorm();
            if (d2 > radius * radius) continue;
            const float* f = avatar_desc_.data() + static_cast<std::size_t>(j) * dims_;
            double dd = 0;
            for (std::size_t k = 0; k < dims_ && dd < best * e * n_shapes; ++k) {
              const double diff = double(f[k]) - double(target[k]);
              dd += diff * diff;
            }
            const double cost = dd / (e * n_shapes) + kPrior * d2 / (radius * radius);
            if (cost < best) best = cost, best_j = j;
          }
        }
    if (best_j < 0) continue;
    geometry::SurfacePoint p;
    double p_cost = std::numeric_limits<double>::infinity();
    const auto j = static_cast<std::size_t>(best_j);
    // A vertex of a few dozen triangles at most in any mesh made for a face; a fan of more is
    // looked at in part.
    const std::int32_t end = std::min(first_triangle_[j + 1], first_triangle_[j] + kMaxFan);
    for (std::int32_t k = first_triangle_[j]; k < end; ++k) {
      const geometry::SurfacePoint q = best_in_triangle(vertex_triangles_[static_cast<std::size_t>(k)], target);
      const double cost = q.squared_distance / (e * n_shapes) + kPrior * (q.point - x).squaredNorm() / (radius * radius);
      if (cost < p_cost) p_cost = cost, p = q;
    }
    if (p.triangle < 0 || p.squared_distance > kExplain * e * n_shapes || on_boundary(p)) continue;
    Match& m = described_[static_cast<std::size_t>(i)];
    m.target = p.point;
    m.weight = data_weight_[static_cast<std::size_t>(i)];
  }
}

void ShapeMatcher::operator()(const Points& skin, const Points& normals, double reach, std::vector<Match>& out) const {
  const bool coarse = reach > kFineReach;
  if (coarse && (searched_reach_ == 0 || reach < 0.5 * searched_reach_)) {
    search(skin, reach);
    searched_reach_ = reach;
  }
  const Triangles& f = surface_->triangles();
  const Points& y = surface_->vertices();
  for (Eigen::Index i = 0; i < skin.rows(); ++i) {
    Match& m = out[static_cast<std::size_t>(i)];
    m.weight = 0;
    const double w = data_weight_[static_cast<std::size_t>(i)];
    if (!(w > 0)) continue;
    if (coarse && described_[static_cast<std::size_t>(i)].weight > 0) {
      m = described_[static_cast<std::size_t>(i)];
      continue;
    }
    const geometry::SurfacePoint p = surface_->closest(skin.row(i).transpose(), reach);
    if (p.triangle < 0 || on_boundary(p)) continue;
    const Eigen::Vector3d a = y.row(f(p.triangle, 0)), b = y.row(f(p.triangle, 1)), c = y.row(f(p.triangle, 2));
    const Eigen::Vector3d fn = (b - a).cross(c - a);
    const double fl = fn.norm();
    if (!(fl > 0) || std::fabs(fn.dot(normals.row(i).transpose())) < kMinNormalCos * fl) continue;
    m.target = p.point;
    m.weight = w;
  }
}

}  // namespace softdeca::fit
