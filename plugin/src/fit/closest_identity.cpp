#include "fit/closest_identity.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "fit/placement.h"

namespace softdeca::fit {

Points identity_points(const TemplateData& t, const std::vector<float>& h) {
  const std::size_t vs = t.skin_vertices;
  Points p(static_cast<Eigen::Index>(vs), 3);
  for (std::size_t v = 0; v < vs; ++v) {
    Eigen::Vector3d x = row3(t.head_neutral, v);
    for (std::size_t k = 0; k < h.size(); ++k) x += static_cast<double>(h[k]) * row3(t.identity_modes + k * vs * 3, v);
    p.row(static_cast<Eigen::Index>(v)) = x.transpose();
  }
  return p;
}

std::vector<float> fit_identity(const TemplateData& t, const std::vector<Match>& matches, const Points& tskin,
                                double prior) {
  constexpr int kRobustRounds = 4;
  constexpr double kRobustScale = 0.001;
  const std::size_t k = t.identity_count, vs = t.skin_vertices;
  const auto kk = static_cast<Eigen::Index>(k);
  std::vector<double> robust(vs, 1.0);
  Eigen::VectorXd h = Eigen::VectorXd::Zero(kk);
  Eigen::MatrixXd rows(3, kk);
  const auto modes_at = [&](std::size_t v) {
    for (std::size_t j = 0; j < k; ++j) rows.col(static_cast<Eigen::Index>(j)) = row3(t.identity_modes + j * vs * 3, v);
  };
  for (int round = 0; round < kRobustRounds; ++round) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Identity(kk, kk) * prior;
    Eigen::VectorXd b = Eigen::VectorXd::Zero(kk);
    for (std::size_t v = 0; v < vs; ++v) {
      const Match& m = matches[v];
      if (!(m.weight > 0)) continue;
      modes_at(v);
      const double w = m.weight * robust[v];
      a.noalias() += w * rows.transpose() * rows;
      b.noalias() += w * rows.transpose() * (m.target - tskin.row(static_cast<Eigen::Index>(v)).transpose());
    }
    h = a.ldlt().solve(b);
    for (std::size_t v = 0; v < vs; ++v) {
      if (!(matches[v].weight > 0)) continue;
      modes_at(v);
      const double r = (rows * h + tskin.row(static_cast<Eigen::Index>(v)).transpose() - matches[v].target).norm();
      robust[v] = 1.0 / (1.0 + (r / kRobustScale) * (r / kRobustScale));
    }
  }
  std::vector<float> out(k);
  for (std::size_t j = 0; j < k; ++j) out[j] = static_cast<float>(h[static_cast<Eigen::Index>(j)]);
  return out;
}

std::vector<float> refine_identity(const TemplateData& t, const geometry::SurfaceQuery& surface,
                                   const std::function<bool(const geometry::SurfacePoint&)>& outside,
                                   std::vector<float> h) {
  // Ten Gauss-Newton steps; a point farther than kReach from the surface is no match, and the
  // Cauchy weight halves a match kRobustScale off (a remesh's flat triangles are far closer).
  constexpr int kIterations = 10;
  constexpr double kReach = 0.005, kRobustScale = 0.0005;
  // h about N(0, 1) against distances good to a tenth of a millimetre.
  constexpr double kPrior = 1e-4 * 1e-4;
  const std::size_t k = t.identity_count, vs = t.skin_vertices;
  if (k == 0 || h.size() != k) return h;
  const auto n = static_cast<Eigen::Index>(k + 6);  // coefficients, rotation, translation
  Eigen::RowVectorXd row(n);
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (int it = 0; it < kIterations; ++it) {
    const Points p = identity_points(t, h);
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
    std::size_t matched = 0;
    for (std::size_t v = 0; v < vs; ++v) {
      const Eigen::Vector3d x = rotation * p.row(static_cast<Eigen::Index>(v)).transpose() + shift;
      const geometry::SurfacePoint c = surface.closest(x, kReach);
      if (c.triangle < 0 || outside(c)) continue;
      const auto tri = surface.triangles().row(c.triangle);
      const Eigen::Vector3d e1 = surface.vertices().row(tri[1]) - surface.vertices().row(tri[0]);
      const Eigen::Vector3d e2 = surface.vertices().row(tri[2]) - surface.vertices().row(tri[0]);
      Eigen::Vector3d normal = e1.cross(e2);
      if (!(normal.norm() > 0)) continue;
      normal.normalize();
      const double r = normal.dot(x - c.point);
      const Eigen::Vector3d turned = rotation.transpose() * normal;  // n . (R m) = (R^T n) . m
      for (std::size_t j = 0; j < k; ++j) row[static_cast<Eigen::Index>(j)] = turned.dot(row3(t.identity_modes + j * vs * 3, v));
      row.segment(static_cast<Eigen::Index>(k), 3) = x.cross(normal).transpose();  // d(n . (w x x)) / dw
      row.segment(static_cast<Eigen::Index>(k) + 3, 3) = normal.transpose();
      const double w = 1.0 / (1.0 + (r / kRobustScale) * (r / kRobustScale));
      a.selfadjointView<Eigen::Lower>().rankUpdate(row.transpose(), w);
      b.noalias() -= w * r * row.transpose();
      ++matched;
    }
    if (matched < 2 * k) break;  // too little of the face on the surface to read the modes
    a.triangularView<Eigen::Upper>() = a.transpose();
    for (std::size_t j = 0; j < k; ++j) {
      const auto jj = static_cast<Eigen::Index>(j);
      a(jj, jj) += kPrior;
      b[jj] -= kPrior * h[j];
    }
    const Eigen::VectorXd step = a.ldlt().solve(b);
    if (!step.allFinite()) break;
    for (std::size_t j = 0; j < k; ++j) h[j] += static_cast<float>(step[static_cast<Eigen::Index>(j)]);
    const Eigen::Vector3d w = step.segment(static_cast<Eigen::Index>(k), 3);
    const Eigen::Matrix3d turn =
        w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() : Eigen::Matrix3d::Identity();
    rotation = turn * rotation;
    shift = turn * shift + step.segment(static_cast<Eigen::Index>(k) + 3, 3);
  }
  return h;
}

}  // namespace softdeca::fit
