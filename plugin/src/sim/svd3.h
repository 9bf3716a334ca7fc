// Small singular value decompositions for the local steps: 3x3 (tets) and 3x2 (triangles).
// Rotation-variant: U and V are rotations, and an inverted element (det F < 0) shows as a
// negative smallest singular value, as projective dynamics needs (Bouaziz et al. 2014).
#pragma once

#include <Eigen/Core>

namespace softdeca::sim {

struct Svd3 {
  Eigen::Matrix3d U, V;  // det = +1
  Eigen::Vector3d sigma;  // sigma(0) >= sigma(1) >= |sigma(2)|
};

// Fast path through the closed-form eigen decomposition of F^T F; falls back to Jacobi SVD
// when the fast result does not reproduce F to near machine precision.
Svd3 svd3(const Eigen::Matrix3d& F);

// Closest matrix with orthonormal columns to a 3x2 F (the rotation part of a triangle's
// deformation gradient), and F's two singular values (descending).
struct Polar32 {
  Eigen::Matrix<double, 3, 2> R;
  Eigen::Vector2d sigma;
};
Polar32 polar32(const Eigen::Matrix<double, 3, 2>& F);

}  // namespace softdeca::sim
