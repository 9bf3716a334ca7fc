// Material parameters of one avatar: each a global value, a map over the skin triangles or a
// map over the skin vertices, turned into the hypernetworks' per-element inputs by the rules
// of docs/bundle.md (face map -> vertex: area-weighted mean of the incident faces; vertex map
// -> face: mean of the three corners). The rules are this file's alone: the training package
// calls them through softdeca_native (models/parameters.py).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bundle/manifest.h"

namespace softdeca::prepare {

// The localisation rules over a skin's triangles (3 indices each). vertex_values: one per
// vertex; face_values and face_area: one per triangle; vertex_area: skin_vertex_areas'.
std::vector<double> skin_vertex_areas(const std::vector<std::int32_t>& triangles, const std::vector<double>& face_area,
                                      std::size_t n_vertices);
// Vertex map -> faces: the mean of each triangle's corners.
void faces_from_vertex_map(const std::vector<std::int32_t>& triangles, const double* vertex_values, double* out);
// Face map -> vertices: the area-weighted mean of the incident faces (0 at a vertex no triangle
// holds).
void vertices_from_face_map(const std::vector<std::int32_t>& triangles, const std::vector<double>& face_area,
                            const std::vector<double>& vertex_area, const double* face_values, double* out);

class ParameterState {
 public:
  enum class Kind { Global, Faces, Vertices };

  ParameterState(const bundle::Manifest& manifest, const std::vector<std::int32_t>& triangles,
                 const std::vector<double>& face_area);

  // Throw Error(INVALID_ARGUMENT / NON_FINITE) for a bad index, count or value.
  void set_global(int index, double value);
  void set_faces(int index, const float* values, std::size_t count);
  void set_vertices(int index, const float* values, std::size_t count);
  void reset();

  Kind kind(int index) const { return values_.at(static_cast<std::size_t>(index)).kind; }
  // Every parameter a global value at its default.
  bool at_defaults() const;
  // The same values (kind, global value and map) for every parameter.
  bool operator==(const ParameterState& other) const;
  // A copy holding only the listed parameters' values, the others at their defaults.
  ParameterState only(const std::vector<int>& indices) const;
  double global(int index) const { return values_.at(static_cast<std::size_t>(index)).global; }

  // Row-major [faces or vertices][columns.size()] raw values for the given parameter columns.
  void face_matrix(const std::vector<int>& columns, float* out) const;
  void vertex_matrix(const std::vector<int>& columns, float* out) const;

 private:
  struct Value {
    Kind kind = Kind::Global;
    double global = 0;
    std::vector<float> map;
  };
  void check_index(int index) const;
  void check_values(int index, const float* values, std::size_t count, std::size_t expected, const char* what) const;
  void column(const Value& v, bool faces, std::vector<float>& out) const;
  // [rows][columns.size()] row-major, one row per face (faces) or vertex.
  void matrix(const std::vector<int>& columns, bool faces, float* out) const;

  const std::vector<ParameterSpec>* specs_;
  const std::vector<std::int32_t>* triangles_;
  std::vector<double> face_area_, vertex_area_;
  std::size_t n_faces_, n_vertices_;
  std::vector<Value> values_;
};

}  // namespace softdeca::prepare
