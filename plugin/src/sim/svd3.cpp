#include "sim/svd3.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>

namespace softdeca::sim {
namespace {
using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

// Any unit vector orthogonal to unit vector a.
Vec3 any_orthogonal(const Vec3& a) {
  const Vec3 e = std::abs(a.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY();
  return (e - a.dot(e) * a).normalized();
}

// SVD from the eigenvectors V of A^T A: U's columns are A v_i, orthonormalised, the third
// the cross product of the first two, so U is a rotation and the sign of det A shows in the
// last singular value. Returns the reconstruction error max|U S V^T - A|.
double from_eigenvectors(const Mat3& A, const Mat3& eigenvectors_ascending, Svd3& r) {
  for (int i = 0; i < 3; ++i) r.V.col(i) = eigenvectors_ascending.col(2 - i);
  if (r.V.determinant() < 0) r.V.col(2) *= -1;
  const Vec3 a0 = A * r.V.col(0), a1 = A * r.V.col(1);
  const double s0 = a0.norm();
  const Vec3 u0 = s0 > 1e-150 ? Vec3(a0 / s0) : Vec3::UnitX();
  Vec3 u1 = a1 - u0.dot(a1) * u0;
  const double n1 = u1.norm();
  u1 = n1 > 1e-12 * (s0 + 1e-300) ? Vec3(u1 / n1) : any_orthogonal(u0);
  r.U.col(0) = u0;
  r.U.col(1) = u1;
  r.U.col(2) = u0.cross(u1);
  for (int i = 0; i < 3; ++i) r.sigma(i) = r.U.col(i).dot(A * r.V.col(i));
  return (r.U * r.sigma.asDiagonal() * r.V.transpose() - A).cwiseAbs().maxCoeff();
}
}  // namespace

Svd3 svd3(const Mat3& F) {
  const double scale = F.cwiseAbs().maxCoeff();
  if (!(scale > 0)) return {Mat3::Identity(), Mat3::Identity(), Vec3::Zero()};
  const Mat3 A = F / scale;  // unit scale keeps the closed form well conditioned
  const Mat3 AtA = A.transpose() * A;
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(AtA);  // closed form: fast, but loses accuracy near repeated eigenvalues
  Svd3 r;
  if (!(from_eigenvectors(A, eig.eigenvectors(), r) < 1e-12)) {
    eig.compute(AtA);  // iterative QR: accurate
    from_eigenvectors(A, eig.eigenvectors(), r);
  }
  r.sigma *= scale;
  return r;
}

Polar32 polar32(const Eigen::Matrix<double, 3, 2>& F) {
  // sqrt of the 2x2 SPD matrix M = F^T F in closed form: (M + sqrt(det M) I) / sqrt(tr M + 2 sqrt(det M)).
  const Eigen::Matrix2d M = F.transpose() * F;
  const double det = M.determinant(), tr = M.trace();
  Polar32 r;
  if (det > 1e-14 * tr * tr) {
    const double s = std::sqrt(det);
    const double t = std::sqrt(tr + 2 * s);
    const Eigen::Matrix2d sqrtM = (M + s * Eigen::Matrix2d::Identity()) / t;
    r.R = F * sqrtM.inverse();
    // Singular values from trace and determinant of sqrt(M): s0 + s1 = t, s0 s1 = s.
    const double disc = std::sqrt(std::max(t * t - 4 * s, 0.0));
    r.sigma = Eigen::Vector2d((t + disc) / 2, (t - disc) / 2);
    return r;
  }
  // Rank-deficient F: V from the eigenvectors, U orthonormalised.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(M);
  const Eigen::Vector2d v0 = eig.eigenvectors().col(1), v1 = eig.eigenvectors().col(0);
  const Vec3 a0 = F * v0;
  const double s0 = a0.norm();
  const Vec3 u0 = s0 > 1e-150 ? Vec3(a0 / s0) : Vec3::UnitX();
  Vec3 u1 = F * v1 - u0.dot(F * v1) * u0;
  u1 = u1.norm() > 1e-12 * (s0 + 1e-300) ? Vec3(u1.normalized()) : any_orthogonal(u0);
  r.R = u0 * v0.transpose() + u1 * v1.transpose();
  r.sigma = Eigen::Vector2d(s0, std::abs(u1.dot(F * v1)));
  return r;
}

}  // namespace softdeca::sim
