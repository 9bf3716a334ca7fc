// The local-global iteration of projective dynamics on one frame: local projections in
// parallel, the prefactored global solve, Anderson acceleration with an energy safeguard,
// convergence by a relative tolerance with an iteration cap.
#pragma once

#include <vector>

#include "sim/model.h"
#include "sim/projections.h"
#include "sim/system.h"
#include "sim/thread_pool.h"

namespace softdeca::sim {

struct SolverSettings {
  int max_iterations = 800;
  // Converged when the estimated RMS distance of the free vertices to the fixed point,
  // residual / (1 - contraction), falls below tolerance * the rest bounding-box diagonal
  // (the residual is the RMS move of one plain PD step; the contraction is measured by plain
  // steps before convergence is accepted).
  double tolerance = 1e-5;
  // Anderson acceleration window (Peng et al. 2018); 0: plain projective dynamics. A step that
  // would raise the energy is replaced by the plain step, so the energy never increases.
  int anderson_window = 5;
  StrainLimit strain_limit = StrainLimit::kNearestInSet;
  int threads = 0;  // 0: all hardware threads
  bool record_energy = true;
  // Collision resolution on S (paper 3.3.2): contact weight (kPa, far above the material
  // weights so the two points coincide), rounds of detect-and-resolve (0: off), and the depth
  // below which a point no longer counts as penetrating (metres).
  double collision_weight = 1e6;
  int collision_rounds = 30;
  double penetration_tolerance = 1e-5;
  // The collision sets' points (the lips) follow their targets on S in the collision step,
  // every frame, with the target term's weights (collisions.h, LipTargets); false: the lips
  // keep the volumetric result and only penetrations are corrected.
  bool lips_follow_targets = true;
  // Elements a solve leaves inverted: projective dynamics' quadratic energies have no barrier
  // at zero volume, so where skin targets pull harder than a small tet's volume term resists
  // (its weight scales with its volume, the targets' with their area) a tet can stay flipped.
  // Real tissue stiffens without bound as it is crushed; the solver approximates that by
  // multiplying the inverted tets' volume and strain weights by `inversion_stiffening` and
  // continuing from the result, at most `inversion_rounds` times (0: off). Counted in
  // SolveStats::inversion_rounds; tets still inverted after the last round are reported.
  int inversion_rounds = 4;
  double inversion_stiffening = 10.0;
};

// Throws Error when a setting is out of range.
void validate(const SolverSettings& s);

struct SolveStats {
  int iterations = 0;
  bool converged = false;
  double relative_step = 0;    // last plain PD step's RMS move / bounding-box diagonal
  double contraction = 0;      // measured contraction of a plain step (slowest mode)
  double estimated_error = 0;  // relative_step / (1 - contraction)
  // PD energy (J) at the last evaluated iterate, and per accepted iterate when recorded: of
  // the material's own weights, so of the solve before any stiffening round (whose stiffened
  // energy is another function; iterations and convergence include the rounds).
  double energy = 0;
  std::vector<double> energy_history;
  int anderson_rejections = 0;
  double target_rms = 0;     // RMS distance of the skin points to their (blended) targets (m)
  double max_target_distance = 0;  // largest distance of a skin point to its (blended) target (m)
  int inverted_elements = 0;       // soft and muscle tets with volume <= 0 at the end of the solve
  int inversion_rounds = 0;        // re-solves with inverted tets stiffened (SolverSettings)
  int stiffened_elements = 0;      // tets stiffened over those rounds
  double local_seconds = 0, global_seconds = 0, factor_seconds = 0, total_seconds = 0;
  // Collisions: penetrating points before and after resolution, contacts used, rounds.
  int penetrating_before = 0, penetrating_after = 0, contacts = 0, collision_rounds = 0;
  double max_contact_gap = 0;  // largest distance between the two points of a contact (m)
  double max_contact_correction = 0;  // largest move of a skin point by the contact step (m)
  int rejected_collision_rounds = 0;  // rounds that moved points beyond the penetration depth
  double collision_seconds = 0;
};

// One frame's problem over a model and a factorised system: P holds the constant rows'
// targets (skin, landmarks, contacts) on entry; x holds the start (pinned vertices placed).
struct FrameProblem {
  const Model* model;
  const System* system;
  const ConstraintGroup* extra = nullptr;  // contacts, rows after the model's
  const Positions* force = nullptr;        // per vertex (N)
  double length_scale = 1;                 // bounding-box diagonal (m)
};

// Runs the PD iterations; x is updated in place, P ends with the last projections.
void run_projective_dynamics(const FrameProblem& problem, Positions& P, Positions& x, const SolverSettings& settings,
                             ThreadPool* pool, SolveStats& stats);

}  // namespace softdeca::sim
