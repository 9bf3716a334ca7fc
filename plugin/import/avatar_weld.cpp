#include "avatar_weld.h"

#include <cstring>
#include <unordered_map>

namespace softdeca::avatar_import {

namespace {
// The neutral position's bits: corners of one control point share them.
struct PositionKey {
  std::uint32_t bits[3];
  bool operator==(const PositionKey& o) const { return std::memcmp(bits, o.bits, sizeof bits) == 0; }
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    return (std::size_t{k.bits[0]} * 73856093u) ^ (std::size_t{k.bits[1]} * 19349663u) ^ (std::size_t{k.bits[2]} * 83492791u);
  }
};

PositionKey key_of(const float* p) {
  PositionKey k;
  std::memcpy(k.bits, p, sizeof k.bits);
  return k;
}
}  // namespace

void weld_corners(SourceMesh& mesh) {
  const std::size_t n = mesh.vertex_count();
  std::vector<const SourceShape*> shapes;
  for (const SourceShape& s : mesh.shapes)
    if (s.deltas.size() == mesh.vertices.size()) shapes.push_back(&s);
  const auto same = [&](std::size_t a, std::size_t b) {
    for (const SourceShape* s : shapes)
      if (std::memcmp(&s->deltas[3 * a], &s->deltas[3 * b], 3 * sizeof(float)) != 0) return false;
    return true;
  };
  std::unordered_map<PositionKey, std::vector<std::size_t>, PositionHash> welded;  // position -> kept vertices there
  std::vector<std::size_t> kept;      // new vertex -> its first corner
  std::vector<std::int32_t> remap(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::size_t>& here = welded[key_of(&mesh.vertices[3 * i])];
    std::size_t target = kept.size();
    for (const std::size_t v : here)
      if (same(kept[v], i)) target = v;
    if (target == kept.size()) {
      here.push_back(target);
      kept.push_back(i);
    }
    remap[i] = static_cast<std::int32_t>(target);
  }
  if (kept.size() == n) return;
  const auto gather = [&](std::vector<float>& values) {
    std::vector<float> out(3 * kept.size());
    for (std::size_t v = 0; v < kept.size(); ++v) std::memcpy(&out[3 * v], &values[3 * kept[v]], 3 * sizeof(float));
    values.swap(out);
  };
  gather(mesh.vertices);
  for (SourceShape& s : mesh.shapes)
    if (s.deltas.size() == 3 * n) gather(s.deltas);
  for (std::int32_t& t : mesh.triangles)
    if (t >= 0 && static_cast<std::size_t>(t) < n) t = remap[static_cast<std::size_t>(t)];  // others: refused later
}

}  // namespace softdeca::avatar_import
