#include "stream/neutral_assembler.h"

#include <algorithm>

namespace softdeca::stream {

bool NeutralAssembler::add(const wire::NeutralChunk& c, std::vector<float>& out) {
  if (c.neutral_id != id_ || c.total_vertices != total_ || xyz_.empty()) {
    id_ = c.neutral_id;  // another mesh: start over
    total_ = c.total_vertices;
    xyz_.assign(3 * total_, 0.0f);
    have_.assign(total_, false);
    have_count_ = 0;
  }
  const std::size_t n = c.xyz.size() / 3;
  std::copy(c.xyz.begin(), c.xyz.end(), xyz_.begin() + static_cast<std::ptrdiff_t>(3 * c.first_vertex));
  for (std::size_t v = c.first_vertex; v < c.first_vertex + n; ++v)
    if (!have_[v]) {
      have_[v] = true;
      ++have_count_;
    }
  if (have_count_ < total_) return false;
  const bool good = wire::neutral_id_of(xyz_.data(), total_) == id_;
  if (good) out = xyz_;
  xyz_.clear();  // used up either way; a bad mesh is re-sent by the sender
  return good;
}

}  // namespace softdeca::stream
