#include "fit/shape_matcher.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace softdeca::fit {

namespace {
constexpr double kMinNormalCos = 0.5;  // a closest point's triangle and the template vertex face alike (either winding)
constexpr double kMinEnergy = 0.005;   // mean squared response (of the largest, per shape) that describes a vertex
constexpr double kExplain = 0.1;       // a match must leave at most this share of the response unexplained
constexpr double kPrior = 0.05;        // the distance's weight in a match's cost, at the search radius
constexpr double kFineReach = 0.006;   // below this reach only closest points: the fine fit

struct CellKey {
  long x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    return static_cast<std::size_t>(k.x * 73856093L ^ k.y * 19349663L ^ k.z * 83492791L);
  }
};

// Each shape's deltas over its largest (one row of `dims` per vertex).
std::vector<double> descriptors(const std::vector<const Points*>& shapes, Eigen::Index rows) {
  const std::size_t dims = 3 * shapes.size();
  std::vector<double> d(static_cast<std::size_t>(rows) * dims, 0.0);
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    const double peak = shapes[s]->rowwise().norm().maxCoeff();
    if (!(peak > 0)) continue;
    for (Eigen::Index v = 0; v < rows; ++v)
      for (int c = 0; c < 3; ++c) d[static_cast<std::size_t>(v) * dims + 3 * s + static_cast<std::size_t>(c)] = (*shapes[s])(v, c) / peak;
  }
  return d;
}

double dot(const double* a, const double* b, std::size_t n) {
  double s = 0;
  for (std::size_t i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}
}  // namespace

ShapeMatcher::ShapeMatcher(const Points& avatar, const Triangles& triangles, std::vector<uint8_t> boundary_edges,
                           std::vector<uint8_t> boundary_vertex, std::vector<double> data_weight,
                           const std::vector<SharedShape>& shapes)
    : boundary_edges_(std::move(boundary_edges)),
      boundary_vertex_(std::move(boundary_vertex)),
      data_weight_(std::move(data_weight)),
      dims_(3 * shapes.size()) {
  surface_ = std::make_unique<geometry::SurfaceQuery>(avatar, triangles);
  std::vector<const Points*> a, t;
  for (const SharedShape& s : shapes) a.push_back(&s.avatar), t.push_back(&s.template_);
  const Eigen::Index vs = static_cast<Eigen::Index>(data_weight_.size());
  avatar_desc_ = descriptors(a, avatar.rows());
  template_desc_ = descriptors(t, vs);
  energy_.assign(static_cast<std::size_t>(vs), 0.0);
  if (dims_)
    for (Eigen::Index v = 0; v < vs; ++v) {
      const double* f = template_desc_.data() + static_cast<std::size_t>(v) * dims_;
      energy_[static_cast<std::size_t>(v)] = dot(f, f, dims_) / static_cast<double>(shapes.size());
    }
  vertex_triangles_.resize(static_cast<std::size_t>(avatar.rows()));
  avatar_skin_.assign(static_cast<std::size_t>(avatar.rows()), 0);
  for (Eigen::Index f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      vertex_triangles_[static_cast<std::size_t>(triangles(f, k))].push_back(static_cast<std::int32_t>(f));
      avatar_skin_[static_cast<std::size_t>(triangles(f, k))] = 1;
    }
  described_.resize(static_cast<std::size_t>(vs));
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

geometry::SurfacePoint ShapeMatcher::best_in_triangle(std::int32_t t, const double* target) const {
  const Triangles& f = surface_->triangles();
  const double* da = avatar_desc_.data() + static_cast<std::size_t>(f(t, 0)) * dims_;
  const double* db = avatar_desc_.data() + static_cast<std::size_t>(f(t, 1)) * dims_;
  const double* dc = avatar_desc_.data() + static_cast<std::size_t>(f(t, 2)) * dims_;
  // |A + u e1 + v e2|^2 over the triangle, A = da - target, e1 = db - da, e2 = dc - da.
  double aa = 0, ae1 = 0, ae2 = 0, e11 = 0, e12 = 0, e22 = 0;
  for (std::size_t i = 0; i < dims_; ++i) {
    const double a = da[i] - target[i], e1 = db[i] - da[i], e2 = dc[i] - da[i];
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
  const double cell = radius;
  const auto key = [&](const Eigen::Vector3d& p) {
    return CellKey{static_cast<long>(std::floor(p[0] / cell)), static_cast<long>(std::floor(p[1] / cell)),
                   static_cast<long>(std::floor(p[2] / cell))};
  };
  std::unordered_map<CellKey, std::vector<std::int32_t>, CellHash> grid;
  for (Eigen::Index j = 0; j < y.rows(); ++j)
    if (avatar_skin_[static_cast<std::size_t>(j)]) grid[key(y.row(j).transpose())].push_back(static_cast<std::int32_t>(j));
  const double n_shapes = static_cast<double>(dims_ / 3);
  for (Eigen::Index i = 0; i < skin.rows(); ++i) {
    const double e = energy_[static_cast<std::size_t>(i)];
    if (!(data_weight_[static_cast<std::size_t>(i)] > 0) || e < kMinEnergy) continue;
    const double* target = template_desc_.data() + static_cast<std::size_t>(i) * dims_;
    const Eigen::Vector3d x = skin.row(i).transpose();
    const CellKey c = key(x);
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
            const double* f = avatar_desc_.data() + static_cast<std::size_t>(j) * dims_;
            double dd = 0;
            for (std::size_t k = 0; k < dims_ && dd < best * e * n_shapes; ++k) dd += (f[k] - target[k]) * (f[k] - target[k]);
            const double cost = dd / (e * n_shapes) + kPrior * d2 / (radius * radius);
            if (cost < best) best = cost, best_j = j;
          }
        }
    if (best_j < 0) continue;
    geometry::SurfacePoint p;
    double p_cost = std::numeric_limits<double>::infinity();
    for (const std::int32_t t : vertex_triangles_[static_cast<std::size_t>(best_j)]) {
      const geometry::SurfacePoint q = best_in_triangle(t, target);
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
