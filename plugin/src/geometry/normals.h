// Area-weighted vertex normals of the whole head (the host's triangles), unit length, zero
// where no incident triangle has area. Two passes without write conflicts (face normals, then
// a gather per vertex), so both split across threads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/aligned.h"

namespace softdeca::geometry {

class Normals {
 public:
  Normals() = default;
  Normals(const std::vector<std::int32_t>& triangles, std::size_t n_vertices);

  std::size_t bytes() const;
  // What both passes read besides the vertices: the triangles and the vertex-to-triangle lists.
  std::size_t topology_bytes() const;
  // Pass 1 for triangles of range `part` of `parts`; pass 2 for vertices of that range.
  void faces(const float* vertices, std::size_t part, std::size_t parts);
  void vertices(float* normals, std::size_t part, std::size_t parts) const;

 private:
  std::vector<std::int32_t> triangles_;
  std::vector<std::int32_t> vertex_ptr_, vertex_faces_;  // CSR: vertex -> incident triangles
  kernels::AlignedArray<float> face_normals_;                     // scratch, 3 per triangle
  std::size_t n_vertices_ = 0;
};

}  // namespace softdeca::geometry
