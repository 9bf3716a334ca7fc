// The avatar's 52 linear blendshapes S_t = neutral + sum_i w_i B_i (paper eq. 7), stored as
// runs of consecutive vertices that a shape moves (gaps of up to kMaxGap unmoved vertices are
// kept as zeros): a frame reads only what shapes move, each run is a contiguous axpy that
// vectorises, and runs split at part boundaries so threads never write the same vertex.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/aligned.h"

namespace softdeca::runtime {

class Blendshapes {
 public:
  static constexpr std::size_t kMaxGap = 4;

  Blendshapes() = default;
  // `deltas`: n_shapes x n_vertices x 3, shape-major. `parts`: how many vertex ranges frames
  // are split into (threads).
  Blendshapes(const float* deltas, std::size_t n_shapes, std::size_t n_vertices, std::size_t parts);

  bool empty() const { return shapes_.empty(); }
  std::size_t bytes() const;
  std::size_t stored_vertices() const;  // vertices stored over all shapes (zeros in gaps included)
  // What blend() reads of the basis for these weights: the runs and deltas of the shapes with a
  // non-zero weight.
  std::size_t bytes_read(const float* weights) const;
  // An upper bound on |sum_i w_i B_i[v]| over the vertices for weights in [0, 1]: sum_i w_i
  // times shape i's largest delta (infinite if a delta is not finite).
  double reach(const float* weights) const;

  // out[v] = neutral[v] + sum_i w_i B_i[v] for the vertices of range `part`.
  void blend(const float* weights, const float* neutral, float* out, std::size_t part) const;

 private:
  struct Run {
    std::uint32_t first_vertex, count, offset;  // offset: first float in deltas_
  };
  struct Shape {
    std::vector<Run> runs;
    std::vector<std::size_t> part_begin;  // first run of each part, plus the end
    std::size_t stored_bytes = 0;         // its runs and their deltas
    float peak = 0;                       // its largest delta (magnitude)
  };
  std::vector<Shape> shapes_;
  kernels::AlignedArray<float> deltas_;  // every shape's runs, one after the other (one huge-page stream)
  std::vector<std::size_t> part_vertex_;  // vertex range bounds, parts + 1
};

}  // namespace softdeca::runtime
