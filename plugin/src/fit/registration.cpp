#include "fit/registration.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace softdeca::fit {

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

Registration register_skin(const Points& start, const Triangles& triangles, const Matcher& matcher,
                           const std::vector<Guide>& guides, const RegistrationSettings& s,
                           const std::function<void(int, int)>& progress) {
  const Eigen::Index n = start.rows();
  const Eigen::SparseMatrix<double> l = laplacian(n, triangles);
  const Eigen::SparseMatrix<double> ltl = Eigen::SparseMatrix<double>(l.transpose()) * l;
  Eigen::SparseMatrix<double> identity(n, n);
  identity.setIdentity();
  // A faint pull to the start keeps vertices no data reaches (closed sockets) determined.
  constexpr double kAnchor = 1e-6;

  Registration r;
  r.skin = start;
  r.matched.assign(static_cast<std::size_t>(n), 0);
  std::vector<Match> matches(static_cast<std::size_t>(n));
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
    matcher(r.skin, normals, reach, matches);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Match& m = matches[static_cast<std::size_t>(i)];
      r.matched[static_cast<std::size_t>(i)] = m.weight > 0;
      if (!(m.weight > 0)) continue;
      diagonal[i] += m.weight;
      rhs.row(i) += m.weight * m.target.transpose();
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
