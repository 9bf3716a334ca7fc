#include "runtime/blendshapes.h"

#include <algorithm>
#include <cstring>

#include "runtime/peak_magnitude.h"

namespace softdeca::runtime {

Blendshapes::Blendshapes(const float* deltas, std::size_t n_shapes, std::size_t n_vertices, std::size_t parts) {
  part_vertex_.resize(parts + 1);
  for (std::size_t p = 0; p <= parts; ++p) part_vertex_[p] = n_vertices * p / parts;
  shapes_.resize(n_shapes);
  std::vector<float> deltas_stored;
  for (std::size_t s = 0; s < n_shapes; ++s) {
    Shape& sh = shapes_[s];
    const float* d = deltas + s * n_vertices * 3;
    const auto moved = [&](std::size_t v) { return d[3 * v] != 0.0f || d[3 * v + 1] != 0.0f || d[3 * v + 2] != 0.0f; };
    sh.part_begin.push_back(0);
    for (std::size_t p = 0; p < parts; ++p) {
      std::size_t v = part_vertex_[p];
      const std::size_t end = part_vertex_[p + 1];
      while (v < end) {
        if (!moved(v)) {
          ++v;
          continue;
        }
        // Extend the run while the next moved vertex is at most kMaxGap away (and in this part).
        std::size_t last = v, probe = v + 1;
        while (probe < end && probe <= last + kMaxGap + 1) {
          if (moved(probe)) last = probe;
          ++probe;
        }
        sh.runs.push_back({static_cast<std::uint32_t>(v), static_cast<std::uint32_t>(last - v + 1),
                           static_cast<std::uint32_t>(deltas_stored.size())});
        deltas_stored.insert(deltas_stored.end(), d + 3 * v, d + 3 * (last + 1));
        v = last + 1;
      }
      sh.part_begin.push_back(sh.runs.size());
    }
    for (const Run& run : sh.runs) sh.stored_bytes += sizeof(Run) + 3 * std::size_t{run.count} * sizeof(float);
    sh.peak = peak_magnitude(d, n_vertices * 3);
  }
  deltas_.resize(deltas_stored.size());
  std::copy(deltas_stored.begin(), deltas_stored.end(), deltas_.data());
}

std::size_t Blendshapes::bytes() const {
  std::size_t b = deltas_.allocated_bytes();
  for (const Shape& s : shapes_) b += s.runs.size() * sizeof(Run) + s.part_begin.size() * sizeof(std::size_t);
  return b;
}

std::size_t Blendshapes::stored_vertices() const {
  return deltas_.size() / 3;
}

std::size_t Blendshapes::bytes_read(const float* weights) const {
  std::size_t b = 0;
  for (std::size_t s = 0; s < shapes_.size(); ++s)
    if (weights[s] != 0.0f) b += shapes_[s].stored_bytes;
  return b;
}

double Blendshapes::reach(const float* weights) const {
  double r = 0;
  for (std::size_t s = 0; s < shapes_.size(); ++s)
    if (weights[s] != 0.0f) r += double(weights[s]) * shapes_[s].peak;
  return r;
}

void Blendshapes::blend(const float* weights, const float* neutral, float* out, std::size_t part) const {
  const std::size_t v0 = part_vertex_[part], v1 = part_vertex_[part + 1];
  std::memcpy(out + 3 * v0, neutral + 3 * v0, (v1 - v0) * 3 * sizeof(float));
  for (std::size_t s = 0; s < shapes_.size(); ++s) {
    const float w = weights[s];
    if (w == 0.0f) continue;
    const Shape& sh = shapes_[s];
    for (std::size_t r = sh.part_begin[part]; r < sh.part_begin[part + 1]; ++r) {
      const Run& run = sh.runs[r];
      float* o = out + 3 * static_cast<std::size_t>(run.first_vertex);
      const float* d = deltas_.data() + run.offset;
      const std::size_t n = 3 * static_cast<std::size_t>(run.count);
      for (std::size_t i = 0; i < n; ++i) o[i] += w * d[i];  // contiguous: the compiler vectorises
    }
  }
}

}  // namespace softdeca::runtime
