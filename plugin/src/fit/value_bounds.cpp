#include "fit/value_bounds.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace softdeca::fit {

MeshExtent mesh_extent(const float* p, std::size_t n) {
  MeshExtent e;
  e.lo = e.hi = e.all_lo = e.all_hi = Eigen::Vector3d::Zero();
  if (n == 0) return e;
  // The outermost 2 % on each side left out, at least one vertex a side from ten vertices on.
  const std::size_t cut = n >= 10 ? std::max<std::size_t>(1, n / 50) : 0;
  std::vector<float> axis(n);
  for (int c = 0; c < 3; ++c) {
    for (std::size_t v = 0; v < n; ++v) axis[v] = p[3 * v + static_cast<std::size_t>(c)];
    const auto [min, max] = std::minmax_element(axis.begin(), axis.end());
    e.all_lo[c] = *min;
    e.all_hi[c] = *max;
    std::nth_element(axis.begin(), axis.begin() + static_cast<std::ptrdiff_t>(cut), axis.end());
    e.lo[c] = axis[cut];
    std::nth_element(axis.begin(), axis.begin() + static_cast<std::ptrdiff_t>(n - 1 - cut), axis.end());
    e.hi[c] = axis[n - 1 - cut];
  }
  return e;
}

std::int64_t stray_vertex(const float* p, std::size_t n, const MeshExtent& e) {
  const double reach = e.stray_distance();
  for (std::size_t v = 0; v < n; ++v) {
    const Eigen::Vector3d x(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    if (x.cwiseAbs().maxCoeff() > kMaxCoordinate) return static_cast<std::int64_t>(v);
    if ((x - x.cwiseMax(e.lo).cwiseMin(e.hi)).norm() > reach) return static_cast<std::int64_t>(v);
  }
  return -1;
}

std::int64_t long_delta(const float* d, std::size_t n, const MeshExtent& e) {
  const double reach = e.max_delta(), reach2 = reach * reach;
  for (std::size_t v = 0; v < n; ++v) {
    const double x = d[3 * v], y = d[3 * v + 1], z = d[3 * v + 2];
    if (x * x + y * y + z * z > reach2) return static_cast<std::int64_t>(v);
  }
  return -1;
}

}  // namespace softdeca::fit
