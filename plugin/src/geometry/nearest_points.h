// Nearest-site queries: for each query point, the index of the nearest of a set of sites
// (ties: the smaller index), exact, over a uniform grid searched ring by ring.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace softdeca::geometry {

using Sites = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Throws std::invalid_argument when `sites` is empty or holds a non-finite value.
std::vector<int32_t> nearest_sites(const Sites& sites, const Sites& queries);

}  // namespace softdeca::geometry
