#include "fit/mesh_topology.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <numeric>

namespace softdeca::fit {
namespace {
std::uint32_t bits(float f) {
  if (f == 0) f = 0;  // -0 and +0 weld
  std::uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}
std::int32_t find(std::vector<std::int32_t>& parent, std::int32_t i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}
std::uint64_t edge_key(std::int32_t a, std::int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}
}  // namespace

// Sorting rather than hashing: a few million vertices weld and count their edges in flat
// arrays (16 bytes an entry) at the speed of a sort.
MeshTopology mesh_topology(const float* p, std::size_t n, const std::int32_t* tri, std::size_t nt) {
  MeshTopology m;
  // Seams split a vertex into copies at exactly the same position: each welds to the first.
  {
    std::vector<std::pair<std::array<std::uint32_t, 3>, std::int32_t>> at(n);
    for (std::size_t v = 0; v < n; ++v) at[v] = {{bits(p[3 * v]), bits(p[3 * v + 1]), bits(p[3 * v + 2])}, static_cast<std::int32_t>(v)};
    std::sort(at.begin(), at.end());
    m.weld.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      m.weld[static_cast<std::size_t>(at[i].second)] = i > 0 && at[i].first == at[i - 1].first ? m.weld[static_cast<std::size_t>(at[i - 1].second)]
                                                                                             : at[i].second;
  }
  const auto welded = [&](std::size_t t, int k) { return m.weld[static_cast<std::size_t>(tri[3 * t + static_cast<std::size_t>(k)])]; };
  const auto degenerate = [&](std::size_t t) {
    return welded(t, 0) == welded(t, 1) || welded(t, 1) == welded(t, 2) || welded(t, 0) == welded(t, 2);
  };
  std::vector<std::int32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  // Edges of the welded mesh: (edge, triangle * 3 + the corner opposite it), sorted by edge.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> edges;
  edges.reserve(3 * nt);
  for (std::size_t t = 0; t < nt; ++t) {
    if (degenerate(t)) {
      ++m.degenerate_triangles;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = welded(t, (k + 1) % 3), b = welded(t, (k + 2) % 3);
      edges.emplace_back(edge_key(a, b), 3 * t + static_cast<std::size_t>(k));
      const std::int32_t ra = find(parent, a), rb = find(parent, b);
      if (ra != rb) parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    }
  }
  m.component.resize(n);
  std::vector<std::int32_t> id(n, -1);  // per root, its part in order of first appearance
  for (std::size_t v = 0; v < n; ++v) {
    const auto root = static_cast<std::size_t>(find(parent, m.weld[v]));
    if (id[root] < 0) id[root] = static_cast<std::int32_t>(m.components++);
    m.component[v] = id[root];
  }
  std::sort(edges.begin(), edges.end());
  m.boundary_edges.assign(nt, 0);
  std::vector<uint8_t> welded_boundary(n, 0);
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const bool alone = (i == 0 || edges[i - 1].first != edges[i].first) &&
                       (i + 1 == edges.size() || edges[i + 1].first != edges[i].first);
    if (!alone) continue;  // an edge of one triangle is open
    const std::size_t t = edges[i].second / 3;
    const int k = static_cast<int>(edges[i].second % 3);
    m.boundary_edges[t] |= static_cast<uint8_t>(1u << k);
    welded_boundary[static_cast<std::size_t>(welded(t, (k + 1) % 3))] = 1;
    welded_boundary[static_cast<std::size_t>(welded(t, (k + 2) % 3))] = 1;
  }
  m.boundary_vertex.resize(n);
  for (std::size_t v = 0; v < n; ++v) m.boundary_vertex[v] = welded_boundary[static_cast<std::size_t>(m.weld[v])];
  return m;
}

}  // namespace softdeca::fit
