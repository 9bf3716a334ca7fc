// The ring search of the uniform grids (nearest_points.cpp, tet_mesh.cpp): a nearest query
// visits the cells around its own ring by ring and stops once no further ring can hold a
// closer item.
#pragma once

#include <algorithm>
#include <cstdlib>

namespace softdeca::geometry {

// Calls visit(x, y, z) for every cell of a dims[0] x dims[1] x dims[2] grid at Chebyshev
// distance r from cell c, z slowest and x fastest (a fixed order keeps ties deterministic).
// Cell and dims: anything indexable by 0..2 with ints (Eigen::Vector3i, std::array<int, 3>).
template <class Cell, class Visit>
void for_each_ring_cell(const Cell& c, int r, const Cell& dims, Visit&& visit) {
  for (int z = c[2] - r; z <= c[2] + r; ++z)
    for (int y = c[1] - r; y <= c[1] + r; ++y)
      for (int x = c[0] - r; x <= c[0] + r; ++x) {
        if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
        if (x < 0 || y < 0 || z < 0 || x >= dims[0] || y >= dims[1] || z >= dims[2]) continue;
        visit(x, y, z);
      }
}

}  // namespace softdeca::geometry
