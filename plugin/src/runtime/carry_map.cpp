#include "runtime/carry_map.h"

namespace softdeca::runtime {

CarryMap::CarryMap(const fit::Embedding& embedding, const std::int32_t* skin_triangles, const Eigen::Matrix3f& to_avatar)
    : to_avatar_(to_avatar) {
  entries_.resize(embedding.size());
  for (std::size_t e = 0; e < embedding.size(); ++e) {
    Entry& x = entries_[e];
    x.vertex = embedding.vertex[e];
    const std::int32_t* tri = skin_triangles + 3 * static_cast<std::size_t>(embedding.triangle[e]);
    for (int k = 0; k < 3; ++k) {
      x.corner[k] = tri[k];
      x.weight[k] = embedding.weight[e] * embedding.bary[3 * e + static_cast<std::size_t>(k)];
    }
  }
}

void CarryMap::carry(const float* field, float* carried) const {
  for (std::size_t e = 0; e < entries_.size(); ++e) Eigen::Map<Eigen::Vector3f>(carried + 3 * e) = this->carried(entries_[e], field, 3, 0);
}

void CarryMap::add(const float* carried, float* out) const {
  for (std::size_t e = 0; e < entries_.size(); ++e) {
    float* o = out + 3 * static_cast<std::size_t>(entries_[e].vertex);
    for (int c = 0; c < 3; ++c) o[c] += carried[3 * e + static_cast<std::size_t>(c)];
  }
}

void CarryMap::add_field(const float* field, float* out) const {
  for (const Entry& e : entries_)
    Eigen::Map<Eigen::Vector3f>(out + 3 * static_cast<std::size_t>(e.vertex)) += carried(e, field, 3, 0);
}

std::vector<float> CarryMap::carry_columns(const float* table, std::size_t k) const {
  std::vector<float> out(entries_.size() * k * 3);
  for (std::size_t e = 0; e < entries_.size(); ++e)
    for (std::size_t j = 0; j < k; ++j)
      Eigen::Map<Eigen::Vector3f>(out.data() + (e * k + j) * 3) = carried(entries_[e], table, k * 3, j * 3);
  return out;
}

}  // namespace softdeca::runtime
