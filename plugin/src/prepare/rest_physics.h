// Physics at prepare (docs/runtime.md): one avatar's head simulated at rest. The bundle's rest
// head (prepare/rest_head.h) is carried to the avatar's neutral skin,
//     V = V0 + K^-1 B^T W (S - B V0),   K = B^T W B + lambda * stiffness(V0),
// the fill's displacement that follows S where S is and spreads smoothly inward (B: S's
// embedding, W: the skin points the fill holds); the teeth are the avatar's own. solve() runs
// the physics' static solve with the skin's targets at the neutral under the avatar's
// parameters, which the frames' rest correction compares across parameter values. The lip and
// lid sets are found on the avatar's neutral (prepare/contact_sets.h), and a parameter map
// reaches a tet through the skin vertex nearest its centroid, as in the training data.
// The training package calls this file through softdeca_native: carry_fill and
// add_fill_stiffness for its carried fills, RestPhysics for its data's rest changes
// (train/rest_changes.py). training/softdeca_train/models/rest_physics.py is its oracle in the
// parity tests.
#pragma once

#include <Eigen/SparseCore>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "bundle/manifest.h"
#include "prepare/parameters.h"
#include "prepare/rest_head.h"
#include "sim/simulator.h"

namespace softdeca::prepare {

// The fill's vertices carried to a neutral skin (skin_vertices x 3, metres).
sim::Positions carry_fill(const RestHead& head, const sim::Positions& neutral_skin);

// Appends scale * (sum over tets of vol * grad(phi_a) . grad(phi_b)), the Dirichlet energy of
// a piecewise-linear field on the fill (the carry's smoothness term), as (a, b, value)
// triplets; a degenerate tet adds nothing.
void add_fill_stiffness(const sim::Positions& x, const sim::TetIndices& tets, double scale,
                        std::vector<Eigen::Triplet<double>>& out);

class RestPhysics {
 public:
  // neutral: the avatar's whole head (head_vertices x 3). Throws Error(INVALID_ARGUMENT) when
  // the carried head is not a valid simulation mesh (an inverted tet: a neutral too far from
  // the template's proportions for the fill to follow).
  RestPhysics(const RestHead& head, const bundle::Manifest& manifest, const float* neutral,
              const std::vector<std::int32_t>& skin_triangles, int threads);

  // The simulated skin at rest (skin_vertices x 3) under the avatar's parameters.
  sim::Positions solve(const ParameterState& params);
  int iterations() const { return iterations_; }  // of the last solve

 private:
  const RestHead& head_;
  const bundle::Manifest& m_;
  sim::Positions targets_;
  std::vector<std::int32_t> soft_tet_vertex_, muscle_tet_vertex_;  // per tet: its skin vertex
  std::unique_ptr<sim::Simulator> sim_;
  int iterations_ = 0;
};

}  // namespace softdeca::prepare
