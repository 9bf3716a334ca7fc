#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <stdexcept>

#include "geometry/nearest_points.h"

using namespace softdeca::geometry;

TEST(NearestSites, MatchesBruteForceInsideAndFarOutside) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  Sites sites(500, 3), queries(300, 3);
  for (Eigen::Index i = 0; i < sites.rows(); ++i) {  // a thin shell, like a skin
    Eigen::Vector3d p(n(rng), n(rng), n(rng));
    sites.row(i) = 0.1 * p.normalized().transpose();
  }
  for (Eigen::Index i = 0; i < queries.rows(); ++i)  // inside, on and far outside the shell
    queries.row(i) = ((0.02 + 0.3 * (i % 3)) * Eigen::Vector3d(n(rng), n(rng), n(rng))).transpose();
  const std::vector<int32_t> found = nearest_sites(sites, queries);
  for (Eigen::Index q = 0; q < queries.rows(); ++q) {
    Eigen::Index best = 0;
    (sites.rowwise() - queries.row(q)).rowwise().squaredNorm().minCoeff(&best);
    EXPECT_EQ(found[static_cast<std::size_t>(q)], best) << q;
  }
}

TEST(NearestSites, RefusesNoSitesAndNonFiniteOnes) {
  Sites none(0, 3), q(1, 3);
  q << 0, 0, 0;
  EXPECT_THROW(nearest_sites(none, q), std::invalid_argument);
  Sites bad(1, 3);
  bad << 0, std::numeric_limits<double>::quiet_NaN(), 0;
  EXPECT_THROW(nearest_sites(bad, q), std::invalid_argument);
}
