#include "prepare/parameters.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace softdeca::prepare {

std::vector<double> skin_vertex_areas(const std::vector<std::int32_t>& triangles, const std::vector<double>& face_area,
                                      std::size_t n_vertices) {
  std::vector<double> area(n_vertices, 0.0);
  for (std::size_t f = 0; f < triangles.size() / 3; ++f)
    for (int c = 0; c < 3; ++c) area[static_cast<std::size_t>(triangles[3 * f + c])] += face_area[f];
  return area;
}

void faces_from_vertex_map(const std::vector<std::int32_t>& t, const double* vertex_values, double* out) {
  const auto v = [&](std::size_t k) { return vertex_values[static_cast<std::size_t>(t[k])]; };
  for (std::size_t f = 0; f < t.size() / 3; ++f) out[f] = (v(3 * f) + v(3 * f + 1) + v(3 * f + 2)) / 3.0;
}

void vertices_from_face_map(const std::vector<std::int32_t>& t, const std::vector<double>& face_area,
                            const std::vector<double>& vertex_area, const double* face_values, double* out) {
  std::fill(out, out + vertex_area.size(), 0.0);
  for (std::size_t f = 0; f < t.size() / 3; ++f)
    for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(t[3 * f + c])] += face_area[f] * face_values[f];
  // an unheld vertex has no area: 0 rather than 0 / 0
  for (std::size_t i = 0; i < vertex_area.size(); ++i) out[i] /= std::max(vertex_area[i], 1e-300);
}

ParameterState::ParameterState(const bundle::Manifest& manifest, const std::vector<std::int32_t>& triangles,
                               const std::vector<double>& face_area)
    : specs_(&manifest.parameters),
      triangles_(&triangles),
      face_area_(face_area),
      vertex_area_(skin_vertex_areas(triangles, face_area, static_cast<std::size_t>(manifest.skin_vertices))),
      n_faces_(triangles.size() / 3),
      n_vertices_(static_cast<std::size_t>(manifest.skin_vertices)) {
  reset();
}

void ParameterState::reset() {
  values_.assign(specs_->size(), Value{});
  for (std::size_t i = 0; i < specs_->size(); ++i) values_[i].global = (*specs_)[i].default_value;
}

bool ParameterState::at_defaults() const {
  for (std::size_t i = 0; i < values_.size(); ++i)
    if (values_[i].kind != Kind::Global || values_[i].global != (*specs_)[i].default_value) return false;
  return true;
}

bool ParameterState::operator==(const ParameterState& other) const {
  if (values_.size() != other.values_.size()) return false;
  for (std::size_t i = 0; i < values_.size(); ++i) {
    const Value &a = values_[i], &b = other.values_[i];
    if (a.kind != b.kind || a.global != b.global || a.map != b.map) return false;
  }
  return true;
}

ParameterState ParameterState::only(const std::vector<int>& indices) const {
  ParameterState out(*this);
  out.reset();
  for (const int i : indices) {
    check_index(i);
    out.values_[static_cast<std::size_t>(i)] = values_[static_cast<std::size_t>(i)];
  }
  return out;
}

void ParameterState::check_index(int index) const {
  require(index >= 0 && static_cast<std::size_t>(index) < specs_->size(),
          "parameter index " + std::to_string(index) + " is not below the bundle's " + std::to_string(specs_->size()) +
              " parameters");
}

void ParameterState::check_values(int index, const float* values, std::size_t count, std::size_t expected,
                                  const char* what) const {
  check_index(index);
  const ParameterSpec& s = (*specs_)[static_cast<std::size_t>(index)];
  require(s.localisable, s.name + " is a global parameter: it cannot vary over the face");
  require_not_null(values, "values");
  require(count == expected, s.name + ": " + std::to_string(count) + " values given, the skin has " +
                                 std::to_string(expected) + " " + what);
  require_finite(values, count, "values");
  for (std::size_t i = 0; i < count; ++i)
    require(values[i] >= s.minimum && values[i] <= s.maximum,
            s.name + ": values[" + std::to_string(i) + "] = " + std::to_string(values[i]) + " is outside [" +
                std::to_string(s.minimum) + ", " + std::to_string(s.maximum) + "]");
}

void ParameterState::set_global(int index, double value) {
  check_index(index);
  const ParameterSpec& s = (*specs_)[static_cast<std::size_t>(index)];
  if (!std::isfinite(value)) throw Error(SOFTDECA_ERROR_NON_FINITE, s.name + ": value is not finite");
  require(value >= s.minimum && value <= s.maximum, s.name + " = " + std::to_string(value) + " is outside [" +
                                                        std::to_string(s.minimum) + ", " + std::to_string(s.maximum) + "]");
  Value& v = values_[static_cast<std::size_t>(index)];
  v.kind = Kind::Global;
  v.global = value;
  v.map.clear();
  v.map.shrink_to_fit();
}

void ParameterState::set_faces(int index, const float* values, std::size_t count) {
  check_values(index, values, count, n_faces_, "triangles");
  Value& v = values_[static_cast<std::size_t>(index)];
  v.kind = Kind::Faces;
  v.map.assign(values, values + count);
}

void ParameterState::set_vertices(int index, const float* values, std::size_t count) {
  check_values(index, values, count, n_vertices_, "vertices");
  Value& v = values_[static_cast<std::size_t>(index)];
  v.kind = Kind::Vertices;
  v.map.assign(values, values + count);
}

void ParameterState::column(const Value& v, bool faces, std::vector<float>& out) const {
  const std::size_t n = faces ? n_faces_ : n_vertices_;
  out.assign(n, static_cast<float>(v.global));
  if (v.kind == Kind::Global) return;
  if ((faces && v.kind == Kind::Faces) || (!faces && v.kind == Kind::Vertices)) {
    out = v.map;
    return;
  }
  const std::vector<double> from(v.map.begin(), v.map.end());
  std::vector<double> to(n);
  if (faces)
    faces_from_vertex_map(*triangles_, from.data(), to.data());
  else
    vertices_from_face_map(*triangles_, face_area_, vertex_area_, from.data(), to.data());
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(to[i]);
}

void ParameterState::face_matrix(const std::vector<int>& columns, float* out) const { matrix(columns, true, out); }

void ParameterState::vertex_matrix(const std::vector<int>& columns, float* out) const { matrix(columns, false, out); }

void ParameterState::matrix(const std::vector<int>& columns, bool faces, float* out) const {
  std::vector<float> col;
  const std::size_t p = columns.size(), rows = faces ? n_faces_ : n_vertices_;
  for (std::size_t c = 0; c < p; ++c) {
    column(values_.at(static_cast<std::size_t>(columns[c])), faces, col);
    for (std::size_t r = 0; r < rows; ++r) out[r * p + c] = col[r];
  }
}

}  // namespace softdeca::prepare
