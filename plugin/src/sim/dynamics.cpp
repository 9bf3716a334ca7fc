#include "sim/dynamics.h"

#include <cmath>
#include <complex>

#include "sim/model.h"

namespace softdeca::sim {

Positions blend_targets(const Positions& S, const Positions& T1, const Positions& T2, const Eigen::VectorXd& gamma,
                        const Eigen::VectorXd& beta) {
  Positions out(S.rows(), 3);
  for (Eigen::Index i = 0; i < S.rows(); ++i) {
    const double a = dynamics_alpha(gamma[i], beta[i]);
    out.row(i) = gamma[i] * S.row(i) + 2 * a * T1.row(i) - beta[i] * T2.row(i);
  }
  return out;
}

double dynamics_spectral_radius(double gamma, double beta) {
  // Roots of z^2 - 2 alpha z + beta.
  const double a = dynamics_alpha(gamma, beta);
  const std::complex<double> disc = std::sqrt(std::complex<double>(a * a - beta, 0));
  return std::max(std::abs(a + disc), std::abs(a - disc));
}

Positions inelastic_previous(const Positions& skin, const Positions& shift, const Positions& previous) {
  Positions out = previous;
  for (Eigen::Index i = 0; i < skin.rows(); ++i) {
    const double length = shift.row(i).norm();
    if (length == 0) continue;
    const Eigen::RowVector3d n = shift.row(i) / length;
    Eigen::RowVector3d v = skin.row(i) - shift.row(i) - previous.row(i);  // before the contact
    const double into = v.dot(n);
    if (into < 0) v -= into * n;
    out.row(i) = skin.row(i) - v;
  }
  return out;
}

}  // namespace softdeca::sim
