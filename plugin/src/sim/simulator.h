// phi† (paper eq. 8, 9, 15, 23): the simulator of one layered head. Owns the mesh, the
// parameter values p and the cached factorisations; solves static frames, batches of them,
// and dynamic sequences. Parameter changes are picked up at the next solve: values that only
// enter the projections (target volume, max strain, gravity, beta) cost nothing, weights and
// skull scales refactorise.
#pragma once

#include <memory>
#include <vector>

#include "sim/bones.h"
#include "sim/collisions.h"
#include "sim/dynamics.h"
#include "sim/mesh.h"
#include "sim/model.h"
#include "sim/parameters.h"
#include "sim/solver.h"
#include "sim/system.h"
#include "sim/thread_pool.h"

namespace softdeca::sim {

struct FrameInput {
  Positions skin_targets;      // S_t: one row per skin point (metres)
  Positions landmark_targets;  // L_t: one row per landmark (SparseSoftDECA), else empty
  BoneTransforms bones;        // rigid transforms of the pinned cranium and jaw
  Positions warm_start;        // start for all simulated vertices; empty: rest (static) or
                               // the previous frame (dynamic, batches)
};

struct FrameResult {
  Positions vertices;  // all simulated vertices
  Positions skin;      // S, through its embedding
  SolveStats stats;
  Positions contact_shift;  // per skin point, what the contact step moved it (empty: no contacts)
};

class Simulator {
 public:
  // Validates the mesh (throws Error with the first problem).
  explicit Simulator(SimulationMesh mesh, const SolverSettings& settings = {});

  const SimulationMesh& mesh() const { return mesh_; }
  ParameterSet& parameters() { return params_; }
  const ParameterSet& parameters() const { return params_; }
  const SolverSettings& settings() const { return settings_; }
  void set_settings(const SolverSettings& settings);

  // One static frame: T = phi†(S_t, p) (eq. 8; eq. 23 when landmarks are given).
  FrameResult solve_static(const FrameInput& input);
  // Frames sharing mesh and parameters over one factorisation, split into contiguous chunks,
  // one per thread; within a chunk each frame starts from the previous one's result.
  std::vector<FrameResult> solve_static_batch(const std::vector<FrameInput>& frames);

  // The next frame of a dynamic sequence (eq. 9). The first frame after reset_dynamics()
  // returns the static solution and seeds T_{t-1} = T_{t-2} with it.
  FrameResult step_dynamic(const FrameInput& input);
  void reset_dynamics() { history_ = DynamicsHistory{}; }
  // The skin's blended target of eq. 9 that the next step_dynamic would solve toward for these
  // skin targets (the targets themselves before the first frame): the S its physics is asked
  // to reach, so the reference a dynamic frame is judged against. Changes nothing.
  Positions dynamic_skin_target(const Positions& skin_targets);
  const DynamicsHistory& dynamics_history() const { return history_; }
  // reset_dynamics() then step_dynamic() over the frames.
  std::vector<FrameResult> solve_sequence(const std::vector<FrameInput>& frames);
  // Independent sequences in parallel (one thread each), sharing the factorisations.
  std::vector<std::vector<FrameResult>> solve_sequences(const std::vector<std::vector<FrameInput>>& sequences);

  // Rest shape with the bones scaled, pinned bones at identity.
  Positions rest_positions() const;
  double length_scale() const { return length_scale_; }
  int thread_count() const { return pool_->size(); }
  int factorizations() const { return factorizations_; }

 private:
  struct Prepared {
    TargetMode mode = TargetMode::kStatic;
    Model model;
    std::unique_ptr<System> system;
    Positions force;
    std::uint64_t revision = 0, matrix_revision = 0;
    double factor_seconds = 0;  // not yet reported
  };
  Prepared& prepare(TargetMode mode);
  void check(const FrameInput& input) const;
  FrameResult solve_frame(const Prepared& prep, const FrameInput& input, const Positions& skin_targets,
                          const Positions& landmark_targets, Positions start, ThreadPool* pool) const;
  // Re-solves with the inverted tets stiffened (SolverSettings::inversion_rounds).
  void stiffen_inverted(const Prepared& prep, const Positions& P0, Positions& x, ThreadPool* pool,
                        SolveStats& stats) const;
  FrameResult dynamic_step(const Prepared& stat, const Prepared& dyn, const FrameInput& input,
                           DynamicsHistory& history, ThreadPool* pool) const;

  SimulationMesh mesh_;
  CollisionTopology collision_topology_;
  ParameterSet params_;
  SolverSettings settings_;
  std::unique_ptr<ThreadPool> pool_;
  Prepared prepared_[2];
  bool has_prepared_[2] = {false, false};
  DynamicsHistory history_;
  double length_scale_ = 1;
  int factorizations_ = 0;
};

// Element counts per parameter domain for a mesh.
DomainSizes domain_sizes(const SimulationMesh& mesh);

}  // namespace softdeca::sim
