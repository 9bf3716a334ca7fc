#include "geometry/normals.h"

#include <cmath>

namespace softdeca::geometry {

Normals::Normals(const std::vector<std::int32_t>& triangles, std::size_t n_vertices)
    : triangles_(triangles), n_vertices_(n_vertices) {
  const std::size_t nt = triangles.size() / 3;
  vertex_ptr_.assign(n_vertices + 1, 0);
  for (const std::int32_t v : triangles) ++vertex_ptr_[static_cast<std::size_t>(v) + 1];
  for (std::size_t v = 0; v < n_vertices; ++v) vertex_ptr_[v + 1] += vertex_ptr_[v];
  vertex_faces_.resize(triangles.size());
  std::vector<std::int32_t> fill(vertex_ptr_.begin(), vertex_ptr_.end() - 1);
  for (std::size_t f = 0; f < nt; ++f)
    for (int c = 0; c < 3; ++c)
      vertex_faces_[static_cast<std::size_t>(fill[static_cast<std::size_t>(triangles[3 * f + c])]++)] = static_cast<std::int32_t>(f);
  face_normals_.resize(nt * 3);
}

std::size_t Normals::bytes() const {
  return topology_bytes() + face_normals_.bytes();
}

std::size_t Normals::topology_bytes() const {
  return (triangles_.size() + vertex_ptr_.size() + vertex_faces_.size()) * sizeof(std::int32_t);
}

void Normals::faces(const float* v, std::size_t part, std::size_t parts) {
  const std::size_t nt = triangles_.size() / 3, f0 = nt * part / parts, f1 = nt * (part + 1) / parts;
  float* out = face_normals_.data();
  for (std::size_t f = f0; f < f1; ++f) {
    const float* a = v + 3 * static_cast<std::size_t>(triangles_[3 * f]);
    const float* b = v + 3 * static_cast<std::size_t>(triangles_[3 * f + 1]);
    const float* c = v + 3 * static_cast<std::size_t>(triangles_[3 * f + 2]);
    const float e1x = b[0] - a[0], e1y = b[1] - a[1], e1z = b[2] - a[2];
    const float e2x = c[0] - a[0], e2y = c[1] - a[1], e2z = c[2] - a[2];
    out[3 * f] = e1y * e2z - e1z * e2y;
    out[3 * f + 1] = e1z * e2x - e1x * e2z;
    out[3 * f + 2] = e1x * e2y - e1y * e2x;
  }
}

void Normals::vertices(float* normals, std::size_t part, std::size_t parts) const {
  const std::size_t v0 = n_vertices_ * part / parts, v1 = n_vertices_ * (part + 1) / parts;
  const float* fn = face_normals_.data();
  for (std::size_t v = v0; v < v1; ++v) {
    float x = 0, y = 0, z = 0;
    for (std::int32_t p = vertex_ptr_[v]; p < vertex_ptr_[v + 1]; ++p) {
      const float* n = fn + 3 * static_cast<std::size_t>(vertex_faces_[static_cast<std::size_t>(p)]);
      x += n[0];
      y += n[1];
      z += n[2];
    }
    const float len = std::sqrt(x * x + y * y + z * z);
    const float inv = len > 0 ? 1.0f / len : 0.0f;
    normals[3 * v] = x * inv;
    normals[3 * v + 1] = y * inv;
    normals[3 * v + 2] = z * inv;
  }
}

}  // namespace softdeca::geometry
