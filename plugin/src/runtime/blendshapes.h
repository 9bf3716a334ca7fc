// The avatar's 52 linear blendshapes S_t = neutral + sum_i w_i B_i (paper eq. 7), stored
// sparsely: per shape only the vertices it moves, sorted, so a frame reads what is nonzero and
// the vertex range can be split between threads without overlap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace softdeca::runtime {

class Blendshapes {
 public:
  Blendshapes() = default;
  // `deltas`: n_shapes x n_vertices x 3, shape-major. `parts`: how many vertex ranges frames
  // are split into (threads).
  Blendshapes(const float* deltas, std::size_t n_shapes, std::size_t n_vertices, std::size_t parts);

  bool empty() const { return shapes_.empty(); }
  std::size_t bytes() const;
  std::size_t nonzeros() const;

  // out[v] = neutral[v] + sum_i w_i B_i[v] for the vertices of range `part` (of `parts`).
  void blend(const float* weights, const float* neutral, float* out, std::size_t part) const;

 private:
  struct Shape {
    std::vector<std::int32_t> vertex;
    std::vector<float> delta;                 // xyz per entry
    std::vector<std::size_t> part_begin;      // first entry of each part, plus the end
  };
  std::vector<Shape> shapes_;
  std::vector<std::size_t> part_vertex_;      // vertex range bounds, parts + 1
};

}  // namespace softdeca::runtime
