// The local-step projections of projective dynamics: each maps a deformation gradient F to
// the closest point P of a constraint set; the element's energy is w |F - P|^2.
#pragma once

#include <Eigen/Core>

#include "sim/svd3.h"

namespace softdeca::sim {

// How strain limiting (eq. 10) projects an element whose largest singular value exceeds eps.
enum class StrainLimit {
  // Closest point of the set SO(3) ∪ {sigma_max <= eps, det >= 0}: no response below eps; above
  // eps, or for an inverted element, the nearer of the rotation and the signed singular values
  // clamped to [0, eps]. A true projection, so the PD energy decreases monotonically and a
  // fixed point exists for every weight (default); no target of it is inverted.
  kNearestInSet,
  // The paper's literal rule: the rotation R whenever sigma_max > eps. Not a projection onto a
  // fixed set: can raise the energy when elements cross eps and can cycle between "on" and
  // "off" when the rotation pulls an element back below eps.
  kPaperRotation,
};

// Singular values s with s0*s1*s2 = target closest to sigma (Newton on the KKT system).
Eigen::Vector3d project_volume_sigma(const Eigen::Vector3d& sigma, double target);

// Closest F' with det F' = target (eq. B.1's set, target sampled in [0.5, 1.5]).
Eigen::Matrix3d project_volume(const Svd3& svd, double target);

// Strain-limiting projection; returns F itself where sigma_max <= eps and F is not inverted
// (no strain response).
Eigen::Matrix3d project_strain_limit(const Eigen::Matrix3d& F, const Svd3& svd, double eps,
                                     StrainLimit mode);

// Rotation part U V^T (eq. B.2's minimiser).
inline Eigen::Matrix3d project_rotation(const Svd3& svd) { return svd.U * svd.V.transpose(); }

}  // namespace softdeca::sim
