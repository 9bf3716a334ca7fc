#include "fit/closest_identity.h"

#include <Eigen/Cholesky>

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

}  // namespace softdeca::fit
