// The template's simulation mesh a bundle carries for the physics at prepare (docs/bundle.md,
// "Rest physics"): the tissue fill's vertices and tets, S's embedding in it, the bones, the
// teeth's surfaces and the rules that find the lip and lid sets on a head. Read and checked
// once at load; prepare/rest_physics.h carries it to each avatar.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bundle/bundle_files.h"
#include "bundle/manifest.h"
#include "prepare/contact_sets.h"
#include "sim/mesh.h"
#include "sim/parameters.h"

namespace softdeca::prepare {

struct RestHead {
  sim::Positions vertices;  // the fill's vertices on the template (metres)
  sim::TetIndices soft_tets, muscle_tets;  // over the fill's vertices
  sim::EmbeddedPoints skin;                // S in the fill: one row per skin vertex
  std::vector<double> carry_weight;        // per skin vertex: 1 where the fill holds it, else 0
  // Head vertex indices of the teeth, appended to the simulated vertices in this order.
  std::vector<std::int32_t> teeth_upper, teeth_lower;
  std::vector<std::int32_t> cranium, jaw;  // simulated vertex indices (fill, then the teeth)
  sim::TriIndices upper_teeth, lower_teeth;  // over teeth_upper's and teeth_lower's order
  bool has_contacts = false;                 // false: no collision sets
  ContactRules contacts;
  double carry_smoothness = 0, tolerance = 0;
  int max_iterations = 0;
  // The physics' id (plugin/data/parameters.json's table) of each of the manifest's
  // parameters, in their order: resolved once at load, so a parameter change never goes back
  // through its name.
  std::vector<sim::Param> parameter_ids;

  std::size_t simulated_vertices() const {
    return static_cast<std::size_t>(vertices.rows()) + teeth_upper.size() + teeth_lower.size();
  }
  std::size_t bytes() const;
};

// Throws Error(FORMAT) naming the first problem: a size that does not match the manifest,
// an index out of range, a non-finite value, embedding weights that do not sum to one, an
// embedding tet with a repeated corner.
RestHead parse_rest_head(const bundle::Manifest& manifest, const bundle::Bytes& data);

}  // namespace softdeca::prepare
