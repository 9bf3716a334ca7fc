// What an avatar mesh's triangles say about it once vertices split at UV seams are welded
// again: its connected parts (a head, eyes, teeth, a body) and the open boundary (a face
// mask's rim), which a seam is not.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace softdeca::fit {

struct MeshTopology {
  std::vector<std::int32_t> weld;       // per vertex: the first vertex at the same position
  std::vector<std::int32_t> component;  // per vertex: its connected part (0 ..)
  std::size_t components = 0;
  std::vector<uint8_t> boundary_edges;   // per triangle: bit k set when the edge opposite corner k is open
  std::vector<uint8_t> boundary_vertex;  // per vertex (welded copies alike)
  std::size_t degenerate_triangles = 0;  // corners at fewer than three positions
};

MeshTopology mesh_topology(const float* positions, std::size_t vertex_count, const std::int32_t* triangles,
                           std::size_t triangle_count);

}  // namespace softdeca::fit
