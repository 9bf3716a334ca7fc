#include "sim/projections.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace softdeca::sim {

Eigen::Vector3d project_volume_sigma(const Eigen::Vector3d& sigma, double target) {
  using Vec3 = Eigen::Vector3d;
  if (std::abs(sigma.prod() - target) <= 1e-14 * target) return sigma;  // already on the set
  // KKT of min |s - sigma|^2 s.t. s0 s1 s2 = target: s_i^2 - sigma_i s_i + mu = 0 for one
  // scalar mu. Parameterised by the last (smallest-sigma) component s2 > 0, mu = s2 (sigma2 - s2)
  // and s0, s1 are the larger roots (sigma_i + sqrt(sigma_i^2 - 4 mu)) / 2. Along s2 the product
  // increases strictly (1/s2 dominates the other terms of d log P / d s2), so the nearest point
  // is the one root of P(s2) = target: a safeguarded 1D Newton solve, exact and robust
  // for large deformations; an inverted element (sigma2 <= 0) returns to positive volume.
  const double s2max = sigma(2);
  auto eval = [&](double s2, Vec3& s, double& slope) {
    const double mu = s2 * (s2max - s2);
    double prod = s2, dmu = s2max - 2 * s2, dlog = 1 / s2;
    s(2) = s2;
    for (int i = 0; i < 2; ++i) {
      const double root = std::sqrt(std::max(sigma(i) * sigma(i) - 4 * mu, 0.0));
      s(i) = 0.5 * (sigma(i) + root);
      prod *= s(i);
      if (root > 0) dlog -= dmu / (s(i) * root);
    }
    // h = P / target - 1 and its derivative.
    slope = dlog * prod / target;
    return prod / target - 1;
  };
  // Bracket [lo, hi] of s2 around the root, from the uniform scaling guess.
  const double p = sigma.prod();
  double x = p > 0 ? sigma(2) * std::cbrt(target / p) : std::cbrt(target);
  double lo = 0, hi = INFINITY;
  Vec3 s;
  double slope = 0;
  for (int it = 0; it < 100; ++it) {
    const double h = eval(x, s, slope);
    if (h > 0) hi = std::min(hi, x);
    else lo = std::max(lo, x);
    double next = x - h / slope;
    if (!(slope > 0) || !(next > lo && next < hi)) next = std::isinf(hi) ? 2 * x : 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-14 * x || std::abs(h) <= 1e-15) break;
    x = next;
  }
  eval(x, s, slope);
  return s;
}

Eigen::Matrix3d project_volume(const Svd3& svd, double target) {
  const Eigen::Vector3d s = project_volume_sigma(svd.sigma, target);
  return svd.U * s.asDiagonal() * svd.V.transpose();
}

Eigen::Matrix3d project_strain_limit(const Eigen::Matrix3d& F, const Svd3& svd, double eps,
                                     StrainLimit mode) {
  // The rotation-variant SVD shows an inverted element as sigma(2) < 0.
  const bool inverted = svd.sigma(2) < 0;
  if (svd.sigma(0) <= eps && !inverted) return F;  // below the limit: no strain response (eq. 10)
  const Eigen::Matrix3d R = project_rotation(svd);
  if (mode == StrainLimit::kPaperRotation) return svd.sigma(0) > eps ? R : F;
  // Closest point of SO(3) ∪ {sigma_max <= eps, det >= 0}: compare the two candidates'
  // distances. The second set excludes inverted elements (its projection clamps the signed
  // singular values to [0, eps]), so no candidate holds an element inverted.
  double to_rotation = 0, to_clamp = 0;
  Eigen::Vector3d clamped;
  for (int i = 0; i < 3; ++i) {
    clamped(i) = std::clamp(svd.sigma(i), 0.0, eps);
    // Distance to the rotation: sigma against +1 (rotation-variant SVD keeps the sign).
    to_rotation += (svd.sigma(i) - 1) * (svd.sigma(i) - 1);
    to_clamp += (svd.sigma(i) - clamped(i)) * (svd.sigma(i) - clamped(i));
  }
  if (to_rotation <= to_clamp) return R;
  return svd.U * clamped.asDiagonal() * svd.V.transpose();
}

}  // namespace softdeca::sim
