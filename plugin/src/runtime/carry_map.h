// How a field over the registered template's skin reaches a fitted avatar's own vertices: each
// carried vertex reads three skin vertices (the corners of the skin triangle it is embedded on)
// with weights (the embedding's weight times its barycentric coordinates), mapped back to the
// avatar's axes and unit by the inverse of the placement's linear part. The map is linear, so
// a table of per-skin-vertex columns carries as the fields it combines do: prepare carries the
// vertex stages' table once, and a frame contracts the carried table (runtime/avatar.h,
// Avatar::evaluate_carried).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fit/avatar_fit.h"

namespace softdeca::runtime {

class CarryMap {
 public:
  // `skin_triangles`: the template's, 3 skin vertex indices each, as the embedding names them.
  CarryMap(const fit::Embedding& embedding, const std::int32_t* skin_triangles, const Eigen::Matrix3f& to_avatar);

  std::size_t size() const { return entries_.size(); }  // carried vertices
  std::size_t bytes() const { return entries_.size() * sizeof(Entry); }

  // carried[e] (size() x 3) = the field (skin vertices x 3) carried onto carried vertex e.
  void carry(const float* field, float* carried) const;
  // out (the avatar's vertices x 3) += each carried vertex's value, at its vertex.
  void add(const float* carried, float* out) const;
  // The same carried in one pass: out += the field carried.
  void add_field(const float* field, float* out) const;
  // A table [skin vertices][k][3] of k fields, each carried: [size()][k][3].
  std::vector<float> carry_columns(const float* table, std::size_t k) const;

 private:
  struct Entry {
    std::int32_t vertex;     // the avatar's
    std::int32_t corner[3];  // skin vertices
    float weight[3];         // the embedding's weight times the barycentric coordinates
  };
  // A * sum_k weight_k field[corner_k] for entry e, over `stride`-float rows, component offset `at`.
  Eigen::Vector3f carried(const Entry& e, const float* field, std::size_t stride, std::size_t at) const {
    Eigen::Vector3f d = Eigen::Vector3f::Zero();
    for (int k = 0; k < 3; ++k)
      d += e.weight[k] * Eigen::Map<const Eigen::Vector3f>(field + static_cast<std::size_t>(e.corner[k]) * stride + at);
    return to_avatar_ * d;
  }

  std::vector<Entry> entries_;
  Eigen::Matrix3f to_avatar_;
};

}  // namespace softdeca::runtime
