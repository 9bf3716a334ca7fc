#include "geometry/nearest_points.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "geometry/grid_ring.h"

namespace softdeca::geometry {

namespace {
// Sites bucketed into cubic cells of a box around them (about two sites per cell).
struct SiteGrid {
  Eigen::Vector3d lo;
  double cell = 1;
  Eigen::Vector3i dims;
  std::vector<int32_t> start, items;  // CSR: the sites of cell c are items[start[c], start[c+1])

  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>(std::floor((p[k] - lo[k]) / cell)), 0, dims[k] - 1);
    return c;
  }
  int index(int x, int y, int z) const { return (z * dims[1] + y) * dims[0] + x; }
};

SiteGrid build(const Sites& s) {
  SiteGrid g;
  g.lo = s.colwise().minCoeff().transpose();
  const Eigen::Vector3d extent = (s.colwise().maxCoeff().transpose() - g.lo).cwiseMax(1e-9);
  const double volume = extent.prod();
  g.cell = std::max(std::cbrt(2.0 * volume / static_cast<double>(s.rows())), extent.maxCoeff() / 256.0);
  for (int k = 0; k < 3; ++k) g.dims[k] = std::max(1, static_cast<int>(std::ceil(extent[k] / g.cell)));
  const std::size_t cells = static_cast<std::size_t>(g.dims.prod());
  std::vector<int32_t> count(cells + 1, 0);
  std::vector<int32_t> cell_of(static_cast<std::size_t>(s.rows()));
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    const Eigen::Vector3i c = g.cell_of(s.row(i).transpose());
    cell_of[static_cast<std::size_t>(i)] = g.index(c[0], c[1], c[2]);
    ++count[static_cast<std::size_t>(cell_of[static_cast<std::size_t>(i)]) + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) count[c + 1] += count[c];
  g.start = count;
  g.items.resize(static_cast<std::size_t>(s.rows()));
  for (Eigen::Index i = 0; i < s.rows(); ++i)
    g.items[static_cast<std::size_t>(count[static_cast<std::size_t>(cell_of[static_cast<std::size_t>(i)])]++)] =
        static_cast<int32_t>(i);
  return g;
}
}  // namespace

std::vector<int32_t> nearest_sites(const Sites& sites, const Sites& queries) {
  if (sites.rows() == 0) throw std::invalid_argument("nearest_sites: no sites");
  if (!sites.allFinite()) throw std::invalid_argument("nearest_sites: a site is not finite");
  const SiteGrid g = build(sites);
  std::vector<int32_t> out(static_cast<std::size_t>(queries.rows()), 0);
  for (Eigen::Index q = 0; q < queries.rows(); ++q) {
    const Eigen::Vector3d p = queries.row(q).transpose();
    const Eigen::Vector3i c = g.cell_of(p);
    double best = std::numeric_limits<double>::infinity();
    int32_t best_i = 0;
    // Ring r holds the cells at Chebyshev distance r from c; a site in ring r + 1 or beyond is
    // at least (r + dist to c's cell walls) away, so stop once that bound passes the best.
    const int rings = g.dims.maxCoeff();
    for (int r = 0; r <= rings; ++r) {
      for_each_ring_cell(c, r, g.dims, [&](int x, int y, int z) {
        const int cell = g.index(x, y, z);
        for (int32_t k = g.start[static_cast<std::size_t>(cell)]; k < g.start[static_cast<std::size_t>(cell) + 1]; ++k) {
          const int32_t i = g.items[static_cast<std::size_t>(k)];
          const double d = (sites.row(i).transpose() - p).squaredNorm();
          if (d < best || (d == best && i < best_i)) {
            best = d;
            best_i = i;
          }
        }
      });
      // Distance from p to the outside of the (2r+1)^3 block of cells around c.
      double wall = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) {
        const double lo = g.lo[k] + (c[k] - r) * g.cell, hi = g.lo[k] + (c[k] + r + 1) * g.cell;
        wall = std::min({wall, p[k] - lo, hi - p[k]});
      }
      if (wall > 0 && best <= wall * wall) break;
    }
    out[static_cast<std::size_t>(q)] = best_i;
  }
  return out;
}

}  // namespace softdeca::geometry
