#include "runtime/blendshapes.h"

#include <algorithm>
#include <cstring>

namespace softdeca::runtime {

Blendshapes::Blendshapes(const float* deltas, std::size_t n_shapes, std::size_t n_vertices, std::size_t parts) {
  part_vertex_.resize(parts + 1);
  for (std::size_t p = 0; p <= parts; ++p) part_vertex_[p] = n_vertices * p / parts;
  shapes_.resize(n_shapes);
  for (std::size_t s = 0; s < n_shapes; ++s) {
    Shape& sh = shapes_[s];
    const float* d = deltas + s * n_vertices * 3;
    for (std::size_t v = 0; v < n_vertices; ++v) {
      if (d[3 * v] == 0.0f && d[3 * v + 1] == 0.0f && d[3 * v + 2] == 0.0f) continue;
      sh.vertex.push_back(static_cast<std::int32_t>(v));
      sh.delta.insert(sh.delta.end(), d + 3 * v, d + 3 * v + 3);
    }
    sh.part_begin.resize(parts + 1);
    for (std::size_t p = 0; p <= parts; ++p)
      sh.part_begin[p] = static_cast<std::size_t>(
          std::lower_bound(sh.vertex.begin(), sh.vertex.end(), static_cast<std::int32_t>(part_vertex_[p])) - sh.vertex.begin());
  }
}

std::size_t Blendshapes::bytes() const {
  std::size_t b = 0;
  for (const Shape& s : shapes_) b += s.vertex.size() * 4 + s.delta.size() * 4 + s.part_begin.size() * sizeof(std::size_t);
  return b;
}

std::size_t Blendshapes::nonzeros() const {
  std::size_t n = 0;
  for (const Shape& s : shapes_) n += s.vertex.size();
  return n;
}

void Blendshapes::blend(const float* weights, const float* neutral, float* out, std::size_t part) const {
  const std::size_t v0 = part_vertex_[part], v1 = part_vertex_[part + 1];
  std::memcpy(out + 3 * v0, neutral + 3 * v0, (v1 - v0) * 3 * sizeof(float));
  for (std::size_t s = 0; s < shapes_.size(); ++s) {
    const float w = weights[s];
    if (w == 0.0f) continue;
    const Shape& sh = shapes_[s];
    const std::int32_t* vi = sh.vertex.data();
    const float* d = sh.delta.data();
    for (std::size_t e = sh.part_begin[part]; e < sh.part_begin[part + 1]; ++e) {
      float* o = out + 3 * static_cast<std::size_t>(vi[e]);
      o[0] += w * d[3 * e];
      o[1] += w * d[3 * e + 1];
      o[2] += w * d[3 * e + 2];
    }
  }
}

}  // namespace softdeca::runtime
