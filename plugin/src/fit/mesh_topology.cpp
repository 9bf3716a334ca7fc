#include "fit/mesh_topology.h"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <unordered_map>

namespace softdeca::fit {
namespace {
struct PositionKey {
  std::uint32_t x, y, z;
  bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    return (static_cast<std::size_t>(k.x) * 73856093u) ^ (static_cast<std::size_t>(k.y) * 19349663u) ^
           (static_cast<std::size_t>(k.z) * 83492791u);
  }
};
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
}  // namespace

MeshTopology mesh_topology(const float* p, std::size_t n, const std::int32_t* tri, std::size_t nt) {
  MeshTopology m;
  // Seams split a vertex into copies at exactly the same position.
  m.weld.resize(n);
  std::unordered_map<PositionKey, std::int32_t, PositionHash> first;
  first.reserve(n);
  for (std::size_t v = 0; v < n; ++v) {
    const PositionKey k{bits(p[3 * v]), bits(p[3 * v + 1]), bits(p[3 * v + 2])};
    m.weld[v] = first.emplace(k, static_cast<std::int32_t>(v)).first->second;
  }
  std::vector<std::int32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  // Edges of the welded mesh, each with how many triangles use it.
  std::unordered_map<std::uint64_t, int> edge_uses;
  edge_uses.reserve(nt * 3);
  const auto edge_key = [](std::int32_t a, std::int32_t b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  for (std::size_t t = 0; t < nt; ++t) {
    const std::int32_t w[3] = {m.weld[static_cast<std::size_t>(tri[3 * t])], m.weld[static_cast<std::size_t>(tri[3 * t + 1])],
                               m.weld[static_cast<std::size_t>(tri[3 * t + 2])]};
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) {
      ++m.degenerate_triangles;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      ++edge_uses[edge_key(w[k], w[(k + 1) % 3])];
      const std::int32_t a = find(parent, w[k]), b = find(parent, w[(k + 1) % 3]);
      if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    }
  }
  m.component.resize(n);
  std::unordered_map<std::int32_t, std::int32_t> ids;
  for (std::size_t v = 0; v < n; ++v) {
    const std::int32_t root = find(parent, m.weld[v]);
    m.component[v] = ids.emplace(root, static_cast<std::int32_t>(ids.size())).first->second;
  }
  m.components = ids.size();
  m.boundary_edges.assign(nt, 0);
  std::vector<uint8_t> welded_boundary(n, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    const std::int32_t w[3] = {m.weld[static_cast<std::size_t>(tri[3 * t])], m.weld[static_cast<std::size_t>(tri[3 * t + 1])],
                               m.weld[static_cast<std::size_t>(tri[3 * t + 2])]};
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) continue;
    for (int k = 0; k < 3; ++k) {
      // the edge opposite corner k joins the other two
      const std::int32_t a = w[(k + 1) % 3], b = w[(k + 2) % 3];
      if (edge_uses[edge_key(a, b)] == 1) {
        m.boundary_edges[t] |= static_cast<uint8_t>(1u << k);
        welded_boundary[static_cast<std::size_t>(a)] = welded_boundary[static_cast<std::size_t>(b)] = 1;
      }
    }
  }
  m.boundary_vertex.resize(n);
  for (std::size_t v = 0; v < n; ++v) m.boundary_vertex[v] = welded_boundary[static_cast<std::size_t>(m.weld[v])];
  return m;
}

}  // namespace softdeca::fit
