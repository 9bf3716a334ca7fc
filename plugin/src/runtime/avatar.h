// One avatar: the host's head (neutral, triangles, optional 52 blendshapes), its identity code,
// material parameters, the current preparation and the per-frame state and buffers.
//
// Threads: evaluate_*, calibrate_landmarks run on one frame thread at a time (a second thread
// gets Error(BUSY)); prepare, parameter and identity setters, set/reset dynamics and stats may
// run on any thread, also while a frame runs. prepare builds a new Preparation and publishes it
// atomically; a frame takes the current one at its start and uses only it, so an output is never
// a mix of two preparations.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "geometry/normals.h"
#include "geometry/rigid.h"
#include "kernels/aligned.h"
#include "kernels/hypertensor.h"
#include "kernels/worker.h"
#include "prepare/parameters.h"
#include "prepare/rest_physics.h"
#include "runtime/blendshapes.h"
#include "runtime/carry_map.h"
#include "runtime/deformation_transfer.h"
#include "runtime/dynamics.h"
#include "runtime/model.h"
#include "runtime/onnx_network.h"

namespace softdeca::runtime {

// How an avatar stores each model's per-element tables. As constructed: the library's choice
// per model (SOFTDECA_PRECISION_DEFAULT), each within its model's parity bound against the
// reference (docs/runtime.md), measured against float storage on the shipped bundle: SoftDECA's
// in int8, which adds at most 0.0051 mm (mean 0.00057 mm) and reads half of half's bytes;
// SparseSoftDECA's in half, as int8 would add 0.025 mm, over its 0.02 mm bound.
struct Precisions {
  kernels::Precision softdeca = kernels::Precision::Int8;  // face_l, vertex_stages, carried_stages
  kernels::Precision sparse = kernels::Precision::Half;    // vertex_l
};

struct AvatarDesc {
  const float* neutral = nullptr;  // head_vertices x 3
  std::size_t vertex_count = 0;
  const std::int32_t* triangles = nullptr;  // the host's triangles over the whole head
  std::size_t triangle_count = 0;
  const float* blendshapes = nullptr;  // 52 x head_vertices x 3 deltas, or null
  std::size_t blendshape_count = 0;
  std::size_t threads = 1;
  Precisions precisions;
  // A fitted avatar's carry map (the avatar is its registered template): prepare also carries
  // the vertex stages onto the map's vertices, for evaluate_carried. Null for other avatars.
  std::shared_ptr<const CarryMap> carry;
};

struct Output {
  float* vertices = nullptr;
  std::size_t vertex_capacity = 0;  // vertices (3 floats each)
  float* normals = nullptr;         // may be null
  std::size_t normal_capacity = 0;
};

// Error(BUFFER_TOO_SMALL) when `out` holds fewer than `vertices` vertices (or normals, when
// it has normals); Error(INVALID_ARGUMENT) without vertices.
void check_output_capacity(const Output& out, std::size_t vertices);

// The least bytes one frame moves between memory and the core, by stage as AvatarStats times
// them (avatar_frame_bytes.cpp): every table a stage reads (the moved shapes' blendshape deltas,
// the hyper-tensors and the vertex and residual stages' tables at their stored precision, DT's
// face blocks and factor, the per-frame networks' weights, the dynamics coefficients and state,
// the normals' topology) counted once at its stored size, the frame's input vertices read once
// and its output (vertices, normals) written once. The avatar's scratch that a frame writes and
// reads back (S_t, right-hand sides, the static result, face normals) and inputs of a few
// hundred bytes (weights, landmarks) are not counted: what a frame must move when nothing of the
// previous one is left in cache and its stages hand over through the cache.
struct FrameBytes {
  std::uint64_t blend = 0, encoder = 0, hyper = 0, solve = 0, dynamics = 0, output = 0, normals = 0;
  std::uint64_t total() const { return blend + encoder + hyper + solve + dynamics + output + normals; }
};

struct AvatarStats {
  std::size_t threads = 1;
  std::uint64_t frames = 0, preparations = 0, generation = 0;
  double frame_ms = 0, encoder_ms = 0, blend_ms = 0, hyper_ms = 0, solve_ms = 0, dynamics_ms = 0, output_ms = 0,
         normals_ms = 0;
  double prepare_ms = 0, prepare_networks_ms = 0, factorisation_ms = 0, prepare_physics_ms = 0;
  int physics_iterations = 0;
  std::uint64_t memory_bytes = 0;
  FrameBytes frame_bytes;  // of the last frame
};

// Everything a frame needs that prepare computes; immutable once published.
struct Preparation {
  std::uint64_t generation = 0;
  std::shared_ptr<const DeformationTransfer> dt;
  std::vector<float> identity;
  kernels::HyperTensor face_l, vertex_l;       // SoftDECA: [F][latent][9]; sparse: [Vs][latent][3]
  // SoftDECA's vertex and residual stages as one table [Vs][latent + modes][3] (empty: neither):
  // the vertex stage's L_v(p, h), weighed by z, then the residual stage's modes, weighed by its
  // coefficients c(w, condition), so that one contraction with (z, c) adds both in one pass.
  kernels::HyperTensor vertex_stages;
  std::vector<float> residual_condition;  // what the residual stage's frame half reads with w
  DynamicsCoefficients dynamics[2];  // by model: 0 SoftDECA, 1 sparse
  // The physics at prepare's correction of SoftDECA's frames, [Vs][3] (empty: none, as at the
  // defaults): c(p) = [P_rest(p) - P_rest(p0)] - [M_rest(p) - M_rest(p_inert)], p_inert being
  // p's rest-inert parameters alone, the others at their defaults (prepare/rest_physics.h).
  // With a rest gate (Manifest::rest_gate) only P_rest(p) - P_rest(p0); the networks' part,
  // -[M1(p) - M1(p_inert)] with the gate open, is in vertex_stages' column of z's last entry,
  // which each frame weighs with its gate (docs/bundle.md, "Rest physics").
  std::vector<float> rest_offset;
  float rest_offset_peak = 0;  // its largest magnitude
  // With a carry map and DT at identity (evaluate_carried): vertex_stages and rest_offset carried
  // onto the map's vertices, [carried][latent + modes][3] and [carried][3] (empty: none).
  kernels::HyperTensor carried_stages;
  std::vector<float> carried_rest;
  std::size_t bytes() const;
};

// A SoftDECA frame's codes computed outside the avatar (runtime/frame_batch.h runs the frame
// networks of several avatars at once): f_w's z (latent floats) and the residual stage's c
// (its modes; null without one), for the preparation they were computed with, which the frame
// then uses whatever prepare has published since.
struct FrameCodes {
  std::shared_ptr<const Preparation> prep;
  const float* z = nullptr;
  const float* c = nullptr;
  double network_ms = 0;  // this avatar's share of the networks' time (its encoder_ms)
};

class Avatar {
 public:
  Avatar(std::shared_ptr<const Model> model, const AvatarDesc& desc);
  ~Avatar();

  const Model& model() const { return *model_; }

  void set_parameter(int index, double value);
  void set_parameter_faces(int index, const float* values, std::size_t count);
  void set_parameter_vertices(int index, const float* values, std::size_t count);
  void reset_parameters();
  void get_parameter(int index, double* value, bool* localised) const;
  void set_identity(const float* values, std::size_t count);
  void get_identity(float* out, std::size_t capacity) const;

  void prepare();

  // `codes`: the frame's z and c as a batch computed them (null: the avatar runs f_w and f_r_w).
  void evaluate_weights(const float* weights, std::size_t count, const Output& out, const FrameCodes* codes = nullptr);
  void evaluate_surface(const float* weights, std::size_t count, const float* surface, std::size_t vertices,
                        const Output& out);
  void evaluate_landmarks(const float* points, std::size_t count, const Output& out);
  void evaluate_linear(const float* weights, std::size_t count, const Output& out);
  // A linear frame blended outside the core (a fitted avatar's own rig): the weights checked and
  // clamped (weights()) and the frame counted; its timings are the caller's.
  void read_frame_weights(const float* weights, std::size_t count);
  // 52 weights as every frame reads them: Error(INVALID_ARGUMENT) for a wrong count, a
  // non-finite weight or one outside [0, 1] by more than the slack; clamped to [0, 1] into `out`.
  static void check_weights(const float* weights, std::size_t count, float* out);
  // The preparation frames use now; Error(NOT_READY) before the first prepare.
  std::shared_ptr<const Preparation> prepared() const;
  void calibrate_landmarks(const float* points, std::size_t count);
  void clear_calibration();

  void set_dynamics(bool enabled) { dynamics_enabled_.store(enabled); }
  void reset_dynamics() { reset_requested_.store(true); }

  AvatarStats stats() const;

  // A fitted avatar's SoftDECA frame (an avatar made with a carry map): the model's correction
  // of the linear blend S_t for 52 weights (checked and clamped as evaluate_weights does), the
  // frame's skin minus S_t with the dynamics when they are on, carried onto the map's vertices
  // (`carried`, CarryMap::size() x 3). With DT at identity and no dynamics the correction is the
  // vertex and residual stages' offsets (and the physics at prepare's) whatever S_t is: the
  // frame then contracts the carried table alone, with no blend of the template. On
  // Error(NON_FINITE) `carried` holds no valid frame (it is the caller's scratch, carried into
  // an output only after a frame succeeds).
  void evaluate_carried(const float* weights, std::size_t count, float* carried, const FrameCodes* codes = nullptr);
  // The 52 weights of the last evaluate_weights or evaluate_linear, checked and clamped to
  // [0, 1] (read_weights). Frame thread only, valid until its next frame.
  const float* weights() const { return weights_.data(); }
  // The avatar's neutral head (head_vertices x 3).
  const std::vector<float>& neutral() const { return neutral_; }

 private:
  std::shared_ptr<const Preparation> current() const;
  // A hypernetwork's values stored at `precision` (its model's), element e holding row order[e]
  // where an order is given.
  kernels::HyperTensor hyper_tensor(const OnnxNetwork& net, const std::vector<float>& parameters,
                           const std::vector<float>& identity, std::size_t n, std::size_t width,
                           kernels::Precision precision, const std::int32_t* order = nullptr) const;
  // The same network's values, checked, before they are stored ([n][latent][width]).
  std::vector<float> hyper_values(const OnnxNetwork& net, const std::vector<float>& parameters,
                                  const std::vector<float>& identity, std::size_t n, std::size_t width) const;
  void read_weights(const float* weights, std::size_t count);
  const float* select_landmarks(const float* points, std::size_t count, const char* what) const;
  // The shared tail of a frame: settle, then the head written to `out` (the skin, and the
  // non-skin vertices from `non_skin` or following the bones) and its normals.
  void finish(const Preparation& prep, int model, const float* skin, const float* non_skin, bool dynamics,
              const Output& out, AvatarStats& st);
  // The dynamics on `skin` (when on) and the check that the result is finite (Error(NON_FINITE)
  // otherwise, before anything is written); returns the frame's final skin.
  const float* settle(const Preparation& prep, int model, const float* skin, bool dynamics, AvatarStats& st);
  // A frame without dynamics forgets their past (a later frame with them starts at rest).
  void settle_static();
  // FrameBytes of each kind of frame (avatar_frame_bytes.cpp), after it ran: `surface`, the
  // vertices of a caller's surface (0: blended from the weights read); `dynamics`, what finish
  // returned; `normals`, whether the output has normals.
  FrameBytes softdeca_bytes(const Preparation& prep, std::size_t surface, bool dynamics, bool normals) const;
  // evaluate_carried's: `blended`, whether it ran the template's whole frame (the dynamics or DT on).
  FrameBytes carried_bytes(const Preparation& prep, bool blended, bool dynamics) const;
  FrameBytes sparse_bytes(const Preparation& prep, bool dynamics, bool normals) const;
  FrameBytes linear_bytes(bool normals) const;
  // The tail's (finish): dynamics, the head written (and the neutral's non-skin vertices read
  // where they follow the bones), normals.
  void add_tail_bytes(const Preparation& prep, int model, bool dynamics, bool rigid_non_skin, bool normals,
                      FrameBytes& b) const;
  // f_w's z and the vertex stages' coefficients (z, c) of the weights read, or `codes`' copied.
  void encode_weights(const Preparation& prep, AvatarStats& st, const FrameCodes* codes);
  // SoftDECA's static skin from the linear skin in head_ into static_: DT (unless every G_f is
  // I), then the vertex stages.
  void softdeca_frame(const Preparation& prep, AvatarStats& st);
  // out = base + the vertex and residual stages' offsets + the physics at prepare's (skin x 3;
  // base may be out itself, or null for the offsets alone); their time joins hyper_ms.
  void add_vertex_stages(const Preparation& prep, const float* base, float* out, AvatarStats& st);
  // Whether the frame of the weights read may be written straight into the caller's output:
  // no dynamics, DT at identity, and every sum it forms provably finite (so it needs no check
  // afterwards that would have to leave the previous output untouched).
  bool in_place(const Preparation& prep, bool dynamics) const;
  // The residual stage's prepare half for these parameters: its condition into `prep`; returns
  // its modes [Vs][modes][3] (empty: no residual stage).
  std::vector<float> prepare_residual(const prepare::ParameterState& params, Preparation& prep) const;
  // SoftDECA's hyper-tensor, vertex and residual stages for these parameters into `prep`;
  // returns the stages' table as computed, [Vs][latent + modes][3] (empty: no stages).
  std::vector<float> prepare_softdeca_stages(const prepare::ParameterState& params, const std::vector<float>& identity,
                                             Preparation& prep) const;
  // The stages' table into `prep` at SoftDECA's precision.
  void store_stages(Preparation& prep, const std::vector<float>& table) const;
  // The networks' part of a preparation for these parameters and identity; `stages` gets
  // SoftDECA's stage table as computed (prepare_softdeca_stages).
  std::shared_ptr<Preparation> prepare_networks(const prepare::ParameterState& params, const std::vector<float>& identity,
                                                std::vector<float>& stages) const;
  // SoftDECA's static frame at rest (zero weights on the neutral) for a preparation, without
  // touching the frame thread's buffers (prepare runs beside frames): M_rest, or with a rest
  // gate M1, the gate open (z's last entry and the residual stage's mean mode at 1).
  std::vector<float> softdeca_rest(const Preparation& prep) const;
  std::vector<float> softdeca_rest(const prepare::ParameterState& params, const std::vector<float>& identity) const;
  // The physics at prepare's correction for these parameters (prepare_mutex_ held): `offset`,
  // Preparation::rest_offset; with a rest gate also `gated`, -[M1(p) - M1(p_inert)], which the
  // frame weighs with its gate (empty without one). iterations: of the physics' solve.
  struct RestCorrection {
    std::vector<float> offset, gated;  // [Vs][3]
  };
  RestCorrection rest_correction(const prepare::ParameterState& params, const Preparation& prep,
                                 const std::vector<float>& identity, int& iterations);
  void write_rigid_non_skin(const float* skin, float* head) const;
  void compute_normals(const float* head, float* normals);
  void record(AvatarStats st);  // a frame's timings, keeping the counters

  std::shared_ptr<const Model> model_;
  const bundle::Manifest& m_;
  std::size_t vh_, vs_, nf_;
  Precisions precisions_;
  std::vector<float> neutral_;  // Vh x 3
  float neutral_peak_;          // its largest magnitude (infinite if one is not finite)
  std::vector<std::int32_t> triangles_;
  SkinGeometry geometry_;
  std::vector<double> neutral_landmarks_;  // K x 3, on the avatar's neutral skin
  std::vector<int> landmark_arkit_;        // K ARKit vertex indices
  std::vector<int> jaw_vertices_, cranium_vertices_;
  Blendshapes blendshapes_;
  kernels::Worker worker_;
  std::shared_ptr<const CarryMap> carry_;

  // Staged inputs of prepare (any thread).
  mutable std::mutex params_mutex_;
  prepare::ParameterState params_;
  std::vector<float> identity_;

  std::mutex prepare_mutex_;
  std::shared_ptr<const DeformationTransfer> dt_;  // built by the first prepare
  // The physics at prepare (bundles with a rest head): the avatar's head, built by the first
  // prepare away from the defaults, and P_rest(p0) and M_rest(p0) (softdeca_rest; for the
  // identity they were computed with); all under prepare_mutex_.
  std::unique_ptr<prepare::RestPhysics> rest_physics_;
  sim::Positions rest_physics0_;
  std::vector<float> rest_model0_, rest_model0_identity_;
  std::uint64_t generation_ = 0;
  mutable std::mutex current_mutex_;
  std::shared_ptr<const Preparation> current_;

  // Frame-thread state.
  std::atomic<bool> busy_{false};
  std::atomic<bool> dynamics_enabled_{false}, reset_requested_{false};
  kernels::AlignedArray<float> weights_, z_, offsets_, head_, static_;
  // The vertex stages' coefficients (z, c): z's copy for the vertex stage (stage_latents_ of
  // them), then the residual stage's frame half's output; and that half's condition input.
  std::size_t stage_latents_, residual_modes_;
  kernels::AlignedArray<float> stage_coefficients_, residual_condition_;
  std::vector<kernels::AlignedArray<float>> rhs_;  // one right-hand side per thread
  std::vector<const float*> rhs_parts_;
  kernels::AlignedArray<double> solve_work_;
  OnnxNetwork::Binding f_w_, f_l_, f_r_w_;
  DynamicsState dynamics_;
  geometry::Normals normals_;
  bool calibrated_ = false;
  geometry::Similarity calibration_;
  std::vector<double> user_neutral_;  // K x 3

  mutable std::mutex stats_mutex_;
  AvatarStats stats_;
};

}  // namespace softdeca::runtime
