// Local-step projections: small SVDs, the volume set, strain limiting.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "sim/projections.h"
#include "sim/svd3.h"

using namespace softdeca::sim;

namespace {
Eigen::Matrix3d random_F(std::mt19937& rng, double spread) {
  std::normal_distribution<double> n(0, spread);
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 9; ++i) F.data()[i] += n(rng);
  return F;
}
}  // namespace

TEST(SimSvd, ReconstructsWithRotationsAndSortedValues) {
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Matrix3d F = random_F(rng, i % 2 ? 0.5 : 1e-4);
    const Svd3 s = svd3(F);
    EXPECT_LT((s.U * s.sigma.asDiagonal() * s.V.transpose() - F).cwiseAbs().maxCoeff(), 1e-11);
    EXPECT_NEAR(s.U.determinant(), 1, 1e-9);
    EXPECT_NEAR(s.V.determinant(), 1, 1e-9);
    EXPECT_GE(s.sigma(0), s.sigma(1));
    EXPECT_GE(s.sigma(1), std::abs(s.sigma(2)));
  }
}

TEST(SimSvd, InvertedElementHasANegativeSmallestValue) {
  const Eigen::Matrix3d F = Eigen::Vector3d(1.2, 0.9, -0.5).asDiagonal();
  const Svd3 s = svd3(F);
  EXPECT_LT(s.sigma(2), 0);
  EXPECT_NEAR(s.sigma.prod(), F.determinant(), 1e-12);
  EXPECT_NEAR(project_rotation(s).determinant(), 1, 1e-12);
}

TEST(SimSvd, DegenerateInputs) {
  for (const Eigen::Matrix3d& F : {Eigen::Matrix3d(Eigen::Matrix3d::Zero()), Eigen::Matrix3d(Eigen::Matrix3d::Identity()),
                                   Eigen::Matrix3d(Eigen::Vector3d(2, 0, 0).asDiagonal()),
                                   Eigen::Matrix3d(Eigen::Vector3d(1, 1, 0).asDiagonal())}) {
    const Svd3 s = svd3(F);
    EXPECT_LT((s.U * s.sigma.asDiagonal() * s.V.transpose() - F).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_NEAR(s.U.determinant(), 1, 1e-12);
  }
}

TEST(SimPolar32, ClosestOrthonormalColumns) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 0.3);
  for (int i = 0; i < 500; ++i) {
    Eigen::Matrix<double, 3, 2> F;
    for (int k = 0; k < 6; ++k) F.data()[k] = n(rng) + (k == 0 || k == 4 ? 1 : 0);
    const Polar32 p = polar32(F);
    EXPECT_LT((p.R.transpose() * p.R - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff(), 1e-10);
    // R^T F is symmetric positive semi-definite for the polar factor.
    const Eigen::Matrix2d S = p.R.transpose() * F;
    EXPECT_NEAR(S(0, 1), S(1, 0), 1e-10);
    EXPECT_GE(S.trace(), 0);
  }
  Eigen::Matrix<double, 3, 2> rank1;
  rank1 << 1, 2, 0, 0, 0, 0;
  const Polar32 p = polar32(rank1);
  EXPECT_LT((p.R.transpose() * p.R - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(SimVolumeProjection, LandsOnTheSetAtTheNearestPoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int i = 0; i < 300; ++i) {
    const Svd3 s = svd3(random_F(rng, i % 3 == 0 ? 0.8 : 0.1));
    for (double target : {0.5, 1.0, 1.5}) {
      const Eigen::Vector3d p = project_volume_sigma(s.sigma, target);
      ASSERT_NEAR(p.prod(), target, 1e-12 * target);
      ASSERT_TRUE((p.array() > 0).all());
      // No point of the set (sampled in log space around p) is nearer.
      const double d = (p - s.sigma).norm();
      for (int k = 0; k < 200; ++k) {
        Eigen::Vector3d q = p.array() * Eigen::Vector3d(u(rng), u(rng), u(rng)).array().exp();
        q *= std::cbrt(target / q.prod());
        ASSERT_GE((q - s.sigma).norm(), d - 1e-9) << "sigma " << s.sigma.transpose() << " target " << target;
      }
    }
  }
  // Inverted elements come back to positive volume.
  const Eigen::Vector3d back = project_volume_sigma(Eigen::Vector3d(1.0, 0.8, -0.2), 1.0);
  EXPECT_NEAR(back.prod(), 1.0, 1e-12);
  EXPECT_TRUE((back.array() > 0).all());
}

TEST(SimStrainLimit, NoResponseBelowEpsilon) {
  const Eigen::Matrix3d F = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                            Eigen::Vector3d(1.15, 1.0, 0.9).asDiagonal();
  const Svd3 s = svd3(F);
  EXPECT_EQ(project_strain_limit(F, s, 1.2, StrainLimit::kNearestInSet), F);
  EXPECT_EQ(project_strain_limit(F, s, 1.2, StrainLimit::kPaperRotation), F);
  // Above epsilon: the paper's rule projects to the rotation; the set projection to the
  // nearer of the rotation and the singular values clamped at epsilon.
  const Eigen::Matrix3d R = project_rotation(s);
  EXPECT_LT((project_strain_limit(F, s, 1.1, StrainLimit::kPaperRotation) - R).norm(), 1e-12);
  const Eigen::Matrix3d C = project_strain_limit(F, s, 1.1, StrainLimit::kNearestInSet);
  EXPECT_NEAR(svd3(C).sigma(0), 1.1, 1e-12);
  EXPECT_LT((C - F).norm(), (R - F).norm());
  // With epsilon below 1 a stretched element goes to its rotation (the nearer point).
  const Eigen::Matrix3d C2 = project_strain_limit(F, s, 0.8, StrainLimit::kNearestInSet);
  EXPECT_LT((C2 - R).norm(), 1e-12);
}

TEST(SimStrainLimit, NoTetProjectionHoldsAnElementInverted) {
  // An element with one vertex pushed through its opposite face (det F < 0), stretched and
  // compressed: every tet projection's target has det >= 0, so no energy keeps it inverted.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (const Eigen::Vector3d& sigma : {Eigen::Vector3d(1.2, 1.0, -0.3), Eigen::Vector3d(0.9, 0.8, -0.2),
                                      Eigen::Vector3d(1.0, 1.0, -1.0), Eigen::Vector3d(1.6, 0.5, -0.4)}) {
    const Eigen::Matrix3d F = turn * sigma.asDiagonal();
    const Svd3 s = svd3(F);
    ASSERT_LT(s.sigma(2), 0);
    EXPECT_GT(project_rotation(s).determinant(), 0.999);
    EXPECT_NEAR(project_volume(s, 1.0).determinant(), 1.0, 1e-9);
    for (const double eps : {0.8, 1.0, 1.05, 2.0}) {
      const Eigen::Matrix3d P = project_strain_limit(F, s, eps, StrainLimit::kNearestInSet);
      EXPECT_GE(P.determinant(), -1e-12) << "sigma " << sigma.transpose() << " eps " << eps;
      // The nearest point of the set: no rotation and no clamped non-inverted point is nearer.
      EXPECT_LE((P - F).norm(), (project_rotation(s) - F).norm() + 1e-12);
      Eigen::Vector3d c = s.sigma;
      for (int i = 0; i < 3; ++i) c(i) = std::clamp(c(i), 0.0, eps);
      EXPECT_LE((P - F).norm(), (s.U * c.asDiagonal() * s.V.transpose() - F).norm() + 1e-12);
    }
  }
}
