#include "fit/registration.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace softdeca::fit {

bool RegistrationTarget::on_boundary(const geometry::SurfacePoint& p) const {
  if (p.triangle < 0) return true;
  constexpr double kEdge = 1e-9;
  const auto t = static_cast<std::size_t>(p.triangle);
  int zero = -1, zeros = 0;
  for (int k = 0; k < 3; ++k)
    if (p.bary[k] <= kEdge) zero = k, ++zeros;
  if (zeros == 0) return false;  // inside the triangle
  if (zeros == 1) return (boundary_edges[t] >> zero) & 1;
  for (int k = 0; k < 3; ++k)  // a corner
    if (p.bary[k] > kEdge)
      return boundary_vertex[static_cast<std::size_t>(surface->triangles()(p.triangle, k))] != 0;
  return true;
}

Points vertex_normals(const Points& v, const Triangles& f) {
  Points n = Points::Zero(v.rows(), 3);
  for (Eigen::Index t = 0; t < f.rows(); ++t) {
    const Eigen::RowVector3d a = v.row(f(t, 0)), b = v.row(f(t, 1)), c = v.row(f(t, 2));
    const Eigen::RowVector3d fn = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) n.row(f(t, k)) += fn;
  }
  for (Eigen::Index i = 0; i < n.rows(); ++i) {
    const double l = n.row(i).norm();
    if (l > 0) n.row(i) /= l;
  }
  return n;
}

namespace {
// The random-walk Laplacian of the mesh's edge graph: (L u)_i = u_i - mean of i's neighbours.
Eigen::SparseMatrix<double> laplacian(Eigen::Index n, const Triangles& f) {
  std::vector<std::vector<std::int32_t>> nb(static_cast<std::size_t>(n));
  for (Eigen::Index t = 0; t < f.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      nb[static_cast<std::size_t>(f(t, k))].push_back(f(t, (k + 1) % 3));
      nb[static_cast<std::size_t>(f(t, (k + 1) % 3))].push_back(f(t, k));
    }
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index i = 0; i < n; ++i) {
    auto& list = nb[static_cast<std::size_t>(i)];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    entries.emplace_back(i, i, 1.0);
    for (const std::int32_t j : list) entries.emplace_back(i, j, -1.0 / static_cast<double>(list.size()));
  }
  Eigen::SparseMatrix<double> l(n, n);
  l.setFromTriplets(entries.begin(), entries.end());
  return l;
}
}  // namespace

Registration register_skin(const Points& start, const Triangles& triangles, const std::vector<double>& data_weight,
                           const RegistrationTarget& target, const std::vector<Guide>& guides,
                           const RegistrationSettings& s, const std::function<void(int, int)>& progress) {
  const Eigen::Index n = start.rows();
  require(static_cast<Eigen::Index>(data_weight.size()) == n, "registration: one data weight per skin vertex");
  const Eigen::SparseMatrix<double> l = laplacian(n, triangles);
  const Eigen::SparseMatrix<double> ltl = Eigen::SparseMatrix<double>(l.transpose()) * l;
  Eigen::SparseMatrix<double> identity(n, n);
  identity.setIdentity();
  // A faint pull to the start keeps vertices no data reaches (closed sockets) determined.
  constexpr double kAnchor = 1e-6;

  Registration r;
  r.skin = start;
  r.matched.assign(static_cast<std::size_t>(n), 0);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  bool analysed = false;
  const int iterations = std::max(1, s.iterations);
  for (int it = 0; it < iterations; ++it) {
    const double t = iterations > 1 ? static_cast<double>(it) / (iterations - 1) : 1.0;
    const double stiffness = s.stiffness_start * std::pow(s.stiffness_end / s.stiffness_start, t);
    const double reach = s.reach_start * std::pow(s.reach_end / s.reach_start, t);
    const double guide = s.guide_weight * (1.0 - 0.9 * t);
    const Points normals = vertex_normals(r.skin, triangles);

    Eigen::VectorXd diagonal = Eigen::VectorXd::Constant(n, kAnchor * stiffness);
    Points rhs = (stiffness * (ltl * start)).eval() + kAnchor * stiffness * start;
    std::fill(r.matched.begin(), r.matched.end(), uint8_t{0});
    for (Eigen::Index i = 0; i < n; ++i) {
      const double w = data_weight[static_cast<std::size_t>(i)];
      if (!(w > 0)) continue;
      const geometry::SurfacePoint p = target.surface->closest(r.skin.row(i).transpose(), reach);
      if (p.triangle < 0 || target.on_boundary(p)) continue;
      const auto& tri = target.surface->triangles();
      const auto& v = target.surface->vertices();
      const Eigen::Vector3d a = v.row(tri(p.triangle, 0)), b = v.row(tri(p.triangle, 1)), c = v.row(tri(p.triangle, 2));
      const Eigen::Vector3d fn = (b - a).cross(c - a);
      const double fl = fn.norm();
      if (!(fl > 0) || std::fabs(fn.dot(normals.row(i).transpose())) < s.min_normal_cos * fl) continue;
      diagonal[i] += w;
      rhs.row(i) += w * p.point.transpose();
      r.matched[static_cast<std::size_t>(i)] = 1;
    }
    for (const Guide& g : guides) {
      diagonal[g.vertex] += guide * g.weight;
      rhs.row(g.vertex) += guide * g.weight * g.target.transpose();
    }
    Eigen::SparseMatrix<double> m = stiffness * ltl;
    m += Eigen::SparseMatrix<double>(diagonal.asDiagonal() * identity);
    if (!analysed) {
      solver.analyzePattern(m);
      analysed = true;
    }
    solver.factorize(m);
    require(solver.info() == Eigen::Success, "registration: the system could not be factorised");
    for (int c = 0; c < 3; ++c) r.skin.col(c) = solver.solve(rhs.col(c));
    if (progress) progress(it + 1, iterations);
  }
  return r;
}

}  // namespace softdeca::fit
