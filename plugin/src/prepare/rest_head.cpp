#include "prepare/rest_head.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "core/binary_reader.h"
#include "core/error.h"

namespace softdeca::prepare {

namespace {
[[noreturn]] void fail(const std::string& message) { throw Error(SOFTDECA_ERROR_FORMAT, message); }

void indices_below(const std::int32_t* v, std::size_t count, std::int64_t bound, const std::string& what) {
  for (std::size_t i = 0; i < count; ++i)
    if (v[i] < 0 || v[i] >= bound)
      fail(what + ": index " + std::to_string(v[i]) + " at " + std::to_string(i) + " is outside [0, " +
           std::to_string(bound) + ")");
}

void finite_values(const double* v, std::size_t count, const std::string& what) {
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(v[i])) fail(what + ": value " + std::to_string(i) + " is not finite");
}
}  // namespace

std::size_t RestHead::bytes() const {
  std::size_t b = static_cast<std::size_t>(vertices.size()) * 8 + static_cast<std::size_t>(soft_tets.size() + muscle_tets.size()) * 4 +
                  static_cast<std::size_t>(skin.vertex.size()) * 12 + carry_weight.size() * 8 +
                  static_cast<std::size_t>(upper_teeth.size() + lower_teeth.size()) * 4;
  for (const auto* v : {&teeth_upper, &teeth_lower, &cranium, &jaw, &contacts.landmarks68, &contacts.lid_candidates})
    b += v->size() * 4;
  return b;
}

RestHead parse_rest_head(const bundle::Manifest& m, const bundle::Bytes& data) {
  RestHead h;
  // Every parameter must be one the physics knows, over a range it accepts.
  const auto& table = sim::parameter_table();
  for (const ParameterSpec& p : m.parameters) {
    const auto it = std::find_if(table.begin(), table.end(), [&](const ParameterSpec& s) { return p.name == s.name; });
    if (it == table.end()) fail("rest_physics: parameter " + p.name + " is not one of the physics' parameters");
    if (p.minimum < it->minimum || p.maximum > it->maximum)
      fail("rest_physics: parameter " + p.name + "'s range is wider than the physics accepts");
    h.parameter_ids.push_back(static_cast<sim::Param>(it - table.begin()));  // the table is in Param's order
  }
  const bundle::RestPhysicsSpec& s = m.rest_physics;
  const std::string& f = s.file;
  BinaryReader in(data.data(), data.size(), f);
  const auto n = static_cast<Eigen::Index>(s.fill_vertices);
  const auto ns = static_cast<Eigen::Index>(m.skin_vertices);
  h.vertices.resize(n, 3);
  in.read(h.vertices.data(), static_cast<std::size_t>(h.vertices.size()), "the fill's vertices");
  h.soft_tets.resize(s.soft_tets, 4);
  in.read(h.soft_tets.data(), static_cast<std::size_t>(h.soft_tets.size()), "soft tets");
  h.muscle_tets.resize(s.muscle_tets, 4);
  in.read(h.muscle_tets.data(), static_cast<std::size_t>(h.muscle_tets.size()), "muscle tets");
  h.skin.vertex.resize(ns, 4);
  in.read(h.skin.vertex.data(), static_cast<std::size_t>(h.skin.vertex.size()), "the skin's embedding vertices");
  h.skin.weight.resize(ns, 4);
  in.read(h.skin.weight.data(), static_cast<std::size_t>(h.skin.weight.size()), "the skin's embedding weights");
  h.carry_weight = in.vector<double>(static_cast<std::size_t>(ns), "carry weights");
  h.teeth_upper = in.vector<std::int32_t>(static_cast<std::size_t>(s.teeth_upper), "upper teeth");
  h.teeth_lower = in.vector<std::int32_t>(static_cast<std::size_t>(s.teeth_lower), "lower teeth");
  h.cranium = in.vector<std::int32_t>(static_cast<std::size_t>(s.cranium), "cranium vertices");
  h.jaw = in.vector<std::int32_t>(static_cast<std::size_t>(s.jaw), "jaw vertices");
  h.upper_teeth.resize(s.upper_teeth_triangles, 3);
  in.read(h.upper_teeth.data(), static_cast<std::size_t>(h.upper_teeth.size()), "upper teeth triangles");
  h.lower_teeth.resize(s.lower_teeth_triangles, 3);
  in.read(h.lower_teeth.data(), static_cast<std::size_t>(h.lower_teeth.size()), "lower teeth triangles");
  h.has_contacts = s.has_contacts;
  h.contacts.landmarks68 = in.vector<std::int32_t>(s.has_contacts ? 68 : 0, "landmarks");
  h.contacts.lid_candidates = in.vector<std::int32_t>(static_cast<std::size_t>(s.lid_candidates), "lid candidates");
  h.contacts.lip_radius = s.lip_radius;
  h.contacts.lip_corner_radius = s.lip_corner_radius;
  h.contacts.lid_reach = s.lid_reach;
  h.contacts.lid_corner_radius = s.lid_corner_radius;
  h.contacts.eye_zone_share = s.eye_zone_share;
  in.finish();

  finite_values(h.vertices.data(), static_cast<std::size_t>(h.vertices.size()), f + " fill vertices");
  finite_values(h.skin.weight.data(), static_cast<std::size_t>(h.skin.weight.size()), f + " skin embedding weights");
  finite_values(h.carry_weight.data(), h.carry_weight.size(), f + " carry weights");
  indices_below(h.soft_tets.data(), static_cast<std::size_t>(h.soft_tets.size()), n, f + " soft tets");
  indices_below(h.muscle_tets.data(), static_cast<std::size_t>(h.muscle_tets.size()), n, f + " muscle tets");
  indices_below(h.skin.vertex.data(), static_cast<std::size_t>(h.skin.vertex.size()), n, f + " skin embedding");
  for (Eigen::Index i = 0; i < ns; ++i)
    if (std::abs(h.skin.weight.row(i).sum() - 1.0) > 1e-6)
      fail(f + ": the embedding weights of skin vertex " + std::to_string(i) + " do not sum to one");
  for (const double w : h.carry_weight)
    if (w < 0 || w > 1) fail(f + ": carry weights must lie in [0, 1]");
  for (const auto* teeth : {&h.teeth_upper, &h.teeth_lower})
    for (const std::int32_t v : *teeth)
      if (v < m.skin_vertices || v >= m.head_vertices)
        fail(f + ": teeth vertex " + std::to_string(v) + " is not a non-skin head vertex");
  const auto total = static_cast<std::int64_t>(h.simulated_vertices());
  indices_below(h.cranium.data(), h.cranium.size(), total, f + " cranium");
  indices_below(h.jaw.data(), h.jaw.size(), total, f + " jaw");
  indices_below(h.upper_teeth.data(), static_cast<std::size_t>(h.upper_teeth.size()),
                static_cast<std::int64_t>(h.teeth_upper.size()), f + " upper teeth triangles");
  indices_below(h.lower_teeth.data(), static_cast<std::size_t>(h.lower_teeth.size()),
                static_cast<std::int64_t>(h.teeth_lower.size()), f + " lower teeth triangles");
  indices_below(h.contacts.landmarks68.data(), h.contacts.landmarks68.size(), ns, f + " landmarks");
  indices_below(h.contacts.lid_candidates.data(), h.contacts.lid_candidates.size(), ns, f + " lid candidates");
  for (Eigen::Index i = 0; i < ns; ++i)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        if (h.skin.vertex(i, a) == h.skin.vertex(i, b))
          fail(f + ": the embedding tet of skin vertex " + std::to_string(i) + " repeats a corner");
  h.carry_smoothness = s.carry_smoothness;
  h.tolerance = s.tolerance;
  h.max_iterations = s.max_iterations;
  return h;
}

}  // namespace softdeca::prepare
