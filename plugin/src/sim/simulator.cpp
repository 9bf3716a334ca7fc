#include "sim/simulator.h"

#include <chrono>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "sim/collisions.h"

namespace softdeca::sim {
namespace {
using Clock = std::chrono::steady_clock;

void check_positions(const Positions& p, Eigen::Index rows, const char* what) {
  require(p.rows() == rows, std::string(what) + " has " + std::to_string(p.rows()) + " rows, expected " +
                                std::to_string(rows));
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(p(i, c)))
        throw Error(SOFTDECA_ERROR_NON_FINITE,
                    std::string(what) + "[" + std::to_string(i) + "][" + std::to_string(c) + "] is not finite");
}

// Tets whose signed volume is not positive: the projections bring an inverted element back,
// so one left at the end of a solve is a failed frame, reported rather than hidden.
bool is_inverted(const TetIndices& tets, Eigen::Index t, const Positions& x) {
  const Eigen::Vector3d a = x.row(tets(t, 0)).transpose();
  const Eigen::Vector3d e1 = x.row(tets(t, 1)).transpose() - a, e2 = x.row(tets(t, 2)).transpose() - a,
                        e3 = x.row(tets(t, 3)).transpose() - a;
  return e1.dot(e2.cross(e3)) <= 0;
}

int inverted_tets(const TetIndices& tets, const Positions& x) {
  int n = 0;
  for (Eigen::Index t = 0; t < tets.rows(); ++t) n += is_inverted(tets, t, x) ? 1 : 0;
  return n;
}

// Multiplies the stiffening of every inverted tet by `factor`; returns how many there were.
int stiffen(const TetIndices& tets, const Positions& x, double factor, Eigen::VectorXd& k) {
  if (k.size() != tets.rows()) k = Eigen::VectorXd::Ones(tets.rows());
  int n = 0;
  for (Eigen::Index t = 0; t < tets.rows(); ++t)
    if (is_inverted(tets, t, x)) {
      k[t] *= factor;
      ++n;
    }
  return n;
}

// The skin target term's element weights (W / 2) per skin point, from the model's group.
Eigen::VectorXd skin_target_weights(const Model& m) {
  for (std::size_t g = 0; g < m.groups.size(); ++g)
    if (m.row_offset[g] == m.skin_row) {
      Eigen::VectorXd w(m.groups[g]->rows());
      m.groups[g]->weights(w);
      return 0.5 * w;
    }
  return {};
}

void fill_rows(Positions& P, Eigen::Index first, const Positions& values) {
  if (first >= 0 && values.rows() > 0) P.middleRows(first, values.rows()) = values;
}
}  // namespace

DomainSizes domain_sizes(const SimulationMesh& m) {
  DomainSizes s{};
  auto set = [&](Domain d, Eigen::Index n) { s[static_cast<std::size_t>(d)] = static_cast<std::size_t>(n); };
  set(Domain::kGlobal, 1);
  set(Domain::kSoftTet, m.soft_tets.rows());
  set(Domain::kMuscleTet, m.muscle_tets.rows());
  set(Domain::kConnectingTet, m.connecting_tets.rows());
  set(Domain::kSkinTriangle, m.skin_triangles.rows());
  set(Domain::kSkullTriangle, m.skull_triangles.rows());
  set(Domain::kVertex, m.vertex_count());
  set(Domain::kSkinPoint, m.skin_count());
  set(Domain::kLandmark, m.landmark_count());
  return s;
}

Simulator::Simulator(SimulationMesh mesh, const SolverSettings& settings)
    : mesh_((validate(mesh), std::move(mesh))), collision_topology_(mesh_), params_(domain_sizes(mesh_)) {
  set_settings(settings);
  length_scale_ = (mesh_.rest.colwise().maxCoeff() - mesh_.rest.colwise().minCoeff()).norm();
}

void Simulator::set_settings(const SolverSettings& s) {
  validate(s);
  const bool rebuild = !pool_ || s.threads != settings_.threads;
  if (s.strain_limit != settings_.strain_limit) has_prepared_[0] = has_prepared_[1] = false;
  settings_ = s;
  if (rebuild) pool_ = std::make_unique<ThreadPool>(s.threads);
}

Positions Simulator::rest_positions() const {
  Positions x = scaled_rest(mesh_, params_);
  place_pinned(mesh_, x, BoneTransforms{}, x);
  return x;
}

Simulator::Prepared& Simulator::prepare(TargetMode mode) {
  const int i = mode == TargetMode::kStatic ? 0 : 1;
  Prepared& p = prepared_[i];
  if (has_prepared_[i] && p.revision == params_.revision()) return p;
  const bool refactor = !has_prepared_[i] || p.matrix_revision != params_.matrix_revision() || !p.system;
  p.mode = mode;
  p.model = build_model(mesh_, params_, mode, settings_.strain_limit);
  p.force = gravity_forces(p.model, params_);
  if (refactor) {
    p.system = std::make_unique<System>(p.model);
    p.factor_seconds += p.system->factor_seconds();
    ++factorizations_;
  }
  p.revision = params_.revision();
  p.matrix_revision = params_.matrix_revision();
  has_prepared_[i] = true;
  return p;
}

void Simulator::check(const FrameInput& in) const {
  check_positions(in.skin_targets, mesh_.skin_count(), "skin_targets");
  if (mesh_.landmark_count() > 0 || in.landmark_targets.rows() > 0)
    check_positions(in.landmark_targets, mesh_.landmark_count(), "landmark_targets");
  check_rigid(in.bones);
  if (in.warm_start.rows() > 0) check_positions(in.warm_start, mesh_.vertex_count(), "warm_start");
}

FrameResult Simulator::solve_frame(const Prepared& prep, const FrameInput& in, const Positions& skin_targets,
                                   const Positions& landmark_targets, Positions x, ThreadPool* pool) const {
  const auto t0 = Clock::now();
  FrameResult r;
  place_pinned(mesh_, prep.model.scaled_rest, in.bones, x);
  Positions P = Positions::Zero(prep.system->rows(), 3);
  fill_rows(P, prep.model.skin_row, skin_targets);
  fill_rows(P, prep.model.landmark_row, landmark_targets);
  const Positions P0 = P;
  FrameProblem problem{&prep.model, prep.system.get(), nullptr, &prep.force, length_scale_};
  run_projective_dynamics(problem, P, x, settings_, pool, r.stats);
  stiffen_inverted(prep, P0, x, pool, r.stats);

  r.skin = embed(mesh_.skin, x);
  // Collisions: a further projective step on S, until no point penetrates (3.3.2).
  if (!mesh_.collisions.empty()) {
    LipTargets lips;
    if (settings_.lips_follow_targets && prep.model.skin_row >= 0) {
      lips.targets = skin_targets;
      lips.weight = skin_target_weights(prep.model);
    }
    CollisionResult c = resolve_collisions(mesh_, collision_topology_, r.skin, x, prep.model.skin_area, settings_, pool,
                                           lips.targets.rows() ? &lips : nullptr);
    r.contact_shift = c.skin - r.skin;
    r.skin = std::move(c.skin);
    r.stats.penetrating_before = c.penetrating_before;
    r.stats.penetrating_after = c.penetrating_after;
    r.stats.contacts = c.contacts;
    r.stats.collision_rounds = c.rounds;
    r.stats.max_contact_gap = c.max_contact_gap;
    r.stats.max_contact_correction = c.max_correction;
    r.stats.rejected_collision_rounds = c.rejected_rounds;
    r.stats.collision_seconds = c.seconds;
  }
  if (skin_targets.rows() > 0) {
    const Eigen::VectorXd d2 = (r.skin - skin_targets).rowwise().squaredNorm();
    r.stats.target_rms = std::sqrt(d2.mean());
    r.stats.max_target_distance = std::sqrt(d2.maxCoeff());
  }
  r.stats.inverted_elements = inverted_tets(mesh_.soft_tets, x) + inverted_tets(mesh_.muscle_tets, x);
  r.vertices = std::move(x);
  r.stats.total_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

void Simulator::stiffen_inverted(const Prepared& prep, const Positions& P0, Positions& x, ThreadPool* pool,
                                 SolveStats& stats) const {
  TetStiffening k;
  for (int round = 0; round < settings_.inversion_rounds; ++round) {
    const int n = stiffen(mesh_.soft_tets, x, settings_.inversion_stiffening, k.soft) +
                  stiffen(mesh_.muscle_tets, x, settings_.inversion_stiffening, k.muscle);
    if (n == 0) return;
    const auto t0 = Clock::now();
    const Model model = build_model(mesh_, params_, prep.mode, settings_.strain_limit, &k);
    const System system(model);
    stats.factor_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    Positions P = P0;
    SolveStats s;
    const FrameProblem problem{&model, &system, nullptr, &prep.force, length_scale_};
    run_projective_dynamics(problem, P, x, settings_, pool, s);
    stats.iterations += s.iterations;
    stats.converged = s.converged;
    stats.estimated_error = s.estimated_error;
    stats.relative_step = s.relative_step;
    stats.contraction = s.contraction;
    stats.local_seconds += s.local_seconds;
    stats.global_seconds += s.global_seconds;
    stats.inversion_rounds = round + 1;
    stats.stiffened_elements += n;
  }
}

FrameResult Simulator::solve_static(const FrameInput& in) {
  check(in);
  Prepared& p = prepare(TargetMode::kStatic);
  FrameResult r = solve_frame(p, in, in.skin_targets, in.landmark_targets,
                              in.warm_start.rows() ? in.warm_start : Positions(p.model.scaled_rest), pool_.get());
  r.stats.factor_seconds += std::exchange(p.factor_seconds, 0.0);
  return r;
}

std::vector<FrameResult> Simulator::solve_static_batch(const std::vector<FrameInput>& frames) {
  for (const auto& f : frames) check(f);
  Prepared& p = prepare(TargetMode::kStatic);
  std::vector<FrameResult> out(frames.size());
  pool_->parallel_for(frames.size(), [&](std::size_t b, std::size_t e, int) {
    Positions start = p.model.scaled_rest;
    for (std::size_t i = b; i < e; ++i) {
      const FrameInput& in = frames[i];
      out[i] = solve_frame(p, in, in.skin_targets, in.landmark_targets, in.warm_start.rows() ? in.warm_start : start,
                           nullptr);
      start = out[i].vertices;
    }
  });
  if (!out.empty()) out[0].stats.factor_seconds += std::exchange(p.factor_seconds, 0.0);
  return out;
}

FrameResult Simulator::dynamic_step(const Prepared& stat, const Prepared& dyn, const FrameInput& in,
                                    DynamicsHistory& h, ThreadPool* pool) const {
  const Model& m = dyn.model;
  if (h.frames == 0) {
    FrameResult r = solve_frame(stat, in, in.skin_targets, in.landmark_targets,
                                in.warm_start.rows() ? in.warm_start : Positions(stat.model.scaled_rest), pool);
    h.skin1 = h.skin2 = r.skin;
    if (mesh_.landmark_count() > 0) h.landmark1 = h.landmark2 = embed_rows(m.landmark_rows, r.vertices);
    h.vertices = r.vertices;
    h.frames = 1;
    return r;
  }
  const Positions skin_target = blend_targets(in.skin_targets, h.skin1, h.skin2, m.skin_gamma, m.skin_beta);
  Positions lmk_target;
  if (mesh_.landmark_count() > 0)
    lmk_target = blend_targets(in.landmark_targets, h.landmark1, h.landmark2, m.landmark_gamma, m.landmark_beta);
  FrameResult r = solve_frame(dyn, in, skin_target, lmk_target, in.warm_start.rows() ? in.warm_start : h.vertices, pool);
  // Contacts are inelastic: their corrections do not enter the momentum (sim/dynamics.h).
  h.skin2 = r.contact_shift.rows() == r.skin.rows() ? inelastic_previous(r.skin, r.contact_shift, h.skin1)
                                                    : std::move(h.skin1);
  h.skin1 = r.skin;
  if (mesh_.landmark_count() > 0) {
    h.landmark2 = std::move(h.landmark1);
    h.landmark1 = embed_rows(m.landmark_rows, r.vertices);
  }
  h.vertices = r.vertices;
  ++h.frames;
  return r;
}

Positions Simulator::dynamic_skin_target(const Positions& skin_targets) {
  check_positions(skin_targets, mesh_.skin_count(), "skin_targets");
  if (history_.frames == 0) return skin_targets;
  const Model& m = prepare(TargetMode::kDynamic).model;
  return blend_targets(skin_targets, history_.skin1, history_.skin2, m.skin_gamma, m.skin_beta);
}

FrameResult Simulator::step_dynamic(const FrameInput& in) {
  check(in);
  Prepared& stat = prepare(TargetMode::kStatic);
  Prepared& dyn = prepare(TargetMode::kDynamic);
  FrameResult r = dynamic_step(stat, dyn, in, history_, pool_.get());
  r.stats.factor_seconds += std::exchange(stat.factor_seconds, 0.0) + std::exchange(dyn.factor_seconds, 0.0);
  return r;
}

std::vector<FrameResult> Simulator::solve_sequence(const std::vector<FrameInput>& frames) {
  for (const auto& f : frames) check(f);
  reset_dynamics();
  std::vector<FrameResult> out;
  out.reserve(frames.size());
  for (const auto& f : frames) out.push_back(step_dynamic(f));
  return out;
}

std::vector<std::vector<FrameResult>> Simulator::solve_sequences(const std::vector<std::vector<FrameInput>>& seqs) {
  for (const auto& s : seqs)
    for (const auto& f : s) check(f);
  const Prepared& stat = prepare(TargetMode::kStatic);
  const Prepared& dyn = prepare(TargetMode::kDynamic);
  std::vector<std::vector<FrameResult>> out(seqs.size());
  pool_->parallel_for(seqs.size(), [&](std::size_t b, std::size_t e, int) {
    for (std::size_t s = b; s < e; ++s) {
      DynamicsHistory h;
      for (const auto& f : seqs[s]) out[s].push_back(dynamic_step(stat, dyn, f, h, nullptr));
    }
  });
  return out;
}

}  // namespace softdeca::sim
