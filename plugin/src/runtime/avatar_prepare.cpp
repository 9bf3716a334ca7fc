#include "runtime/avatar.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include "core/error.h"
#include "runtime/avatar_detail.h"
#include "runtime/peak_magnitude.h"

namespace softdeca::runtime {

using namespace avatar_detail;

namespace {
// Per element, a's rows [n][ka][3] followed by b's [n][kb][3]: [n][ka + kb][3].
std::vector<float> side_by_side(const std::vector<float>& a, std::size_t ka, const std::vector<float>& b, std::size_t kb,
                                std::size_t n) {
  std::vector<float> joint(n * (ka + kb) * 3);
  for (std::size_t e = 0; e < n; ++e) {
    float* row = joint.data() + e * (ka + kb) * 3;
    std::copy_n(a.data() + e * ka * 3, ka * 3, row);
    std::copy_n(b.data() + e * kb * 3, kb * 3, row + ka * 3);
  }
  return joint;
}

// `add` [n][3] into column `column` of `table` [n][width][3].
void add_to_column(std::vector<float>& table, std::size_t width, std::size_t column, const std::vector<float>& add,
                   std::size_t n) {
  for (std::size_t e = 0; e < n; ++e)
    for (std::size_t c = 0; c < 3; ++c) table[(e * width + column) * 3 + c] += add[e * 3 + c];
}
}  // namespace

// A hypernetwork's L(p, h) for n elements of the given width, checked.
std::vector<float> Avatar::hyper_values(const OnnxNetwork& net, const std::vector<float>& parameters,
                                        const std::vector<float>& identity, std::size_t n, std::size_t width) const {
  std::vector<float> l(n * static_cast<std::size_t>(m_.latent) * width);
  net.run({parameters.data(), identity.data()}, {l.data()}, 1);
  if (!all_finite(l.data(), l.size()))
    throw Error(SOFTDECA_ERROR_FORMAT, net.spec().key + " produced non-finite values for these parameters");
  return l;
}

// The same, stored.
kernels::HyperTensor Avatar::hyper_tensor(const OnnxNetwork& net, const std::vector<float>& parameters,
                                 const std::vector<float>& identity, std::size_t n, std::size_t width,
                                 kernels::Precision precision, const std::int32_t* order) const {
  return kernels::HyperTensor(hyper_values(net, parameters, identity, n, width).data(), n, m_.latent, static_cast<int>(width),
                              precision, order);
}

std::size_t Preparation::bytes() const {
  return face_l.bytes() + vertex_l.bytes() + vertex_stages.bytes() + residual_condition.size() * 4 + dynamics[0].bytes() +
         dynamics[1].bytes() + identity.size() * 4 + rest_offset.size() * 4 + carried_stages.bytes() + carried_rest.size() * 4;
}

void Avatar::prepare() {
  std::lock_guard<std::mutex> prepare_lock(prepare_mutex_);
  const auto t0 = Clock::now();
  std::vector<float> identity;
  std::unique_ptr<prepare::ParameterState> params;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params = std::make_unique<prepare::ParameterState>(params_);
    identity = identity_;
  }
  double factorisation_ms = 0;
  if (!dt_ && model_->has(false)) {
    const auto f0 = Clock::now();
    dt_ = std::make_shared<const DeformationTransfer>(geometry_, vs_, model_->skin_triangles(), m_.dt_regularisation,
                                                      worker_.parts());
    factorisation_ms = ms(f0, Clock::now());
  }
  const auto n0 = Clock::now();
  std::vector<float> stages;  // SoftDECA's stage table as computed, before its storage rounding
  std::shared_ptr<Preparation> prep = prepare_networks(*params, identity, stages);
  double networks_ms = ms(n0, Clock::now());
  // The physics at prepare: nothing to correct at the defaults (c(p0) = 0).
  double physics_ms = 0;
  int physics_iterations = 0;
  if (model_->rest_head() && model_->has(false) && !params->at_defaults()) {
    const auto r0 = Clock::now();
    RestCorrection rest = rest_correction(*params, *prep, identity, physics_iterations);
    prep->rest_offset = std::move(rest.offset);
    prep->rest_offset_peak = peak_magnitude(prep->rest_offset.data(), prep->rest_offset.size());
    if (!rest.gated.empty()) {  // into the column the gate weighs, stored again from the values
      add_to_column(stages, stage_latents_ + residual_modes_, stage_latents_ - 1, rest.gated, vs_);
      store_stages(*prep, stages);
    }
    if (carry_ && prep->face_l.zero()) {
      prep->carried_rest.resize(carry_->size() * 3);
      carry_->carry(prep->rest_offset.data(), prep->carried_rest.data());
    }
    physics_ms = ms(r0, Clock::now());
  }
  if (carry_ && prep->face_l.zero() && !stages.empty()) {  // carried from the values, not their stored rounding
    const auto c0 = Clock::now();
    const std::size_t latents = stage_latents_ + residual_modes_;
    prep->carried_stages = kernels::HyperTensor(carry_->carry_columns(stages.data(), latents).data(), carry_->size(),
                                                static_cast<int>(latents), 3, precisions_.softdeca);
    networks_ms += ms(c0, Clock::now());
  }
  {
    std::lock_guard<std::mutex> lock(current_mutex_);
    prep->generation = ++generation_;
    current_ = std::move(prep);
  }
  std::lock_guard<std::mutex> lock(stats_mutex_);
  stats_.preparations += 1;
  stats_.prepare_ms = ms(t0, Clock::now());
  stats_.prepare_networks_ms = networks_ms;
  stats_.prepare_physics_ms = physics_ms;
  stats_.physics_iterations = physics_iterations;
  if (factorisation_ms > 0) stats_.factorisation_ms = factorisation_ms;
}

// SoftDECA's stages for these parameters: its per-face hyper-tensor, its vertex stage and the
// residual stage's prepare half (what softdeca_rest reads).
std::vector<float> Avatar::prepare_softdeca_stages(const prepare::ParameterState& params, const std::vector<float>& identity,
                                                   Preparation& prep) const {
  const OnnxNetwork& hyper = *model_->hyper(false);
  const auto& cols = hyper.spec().parameter_columns;
  std::vector<float> p(nf_ * cols.size());
  params.face_matrix(cols, p.data());
  // In the deformation transfer's face order (its FaceBlocks).
  prep.face_l = hyper_tensor(hyper, p, identity, nf_, 9, precisions_.softdeca, dt_->face_order().data());
  std::vector<float> vertex_l;
  if (const OnnxNetwork* stage = model_->softdeca_vertex_stage()) {
    std::vector<float> pv(vs_ * stage->spec().parameter_columns.size());
    params.vertex_matrix(stage->spec().parameter_columns, pv.data());
    vertex_l = hyper_values(*stage, pv, identity, vs_, 3);
  }
  const std::vector<float> modes = prepare_residual(params, prep);
  if (stage_latents_ + residual_modes_ == 0) return {};
  std::vector<float> table = side_by_side(vertex_l, stage_latents_, modes, residual_modes_, vs_);
  store_stages(prep, table);
  return table;
}

void Avatar::store_stages(Preparation& prep, const std::vector<float>& table) const {
  const auto latents = static_cast<int>(stage_latents_ + residual_modes_);
  prep.vertex_stages = kernels::HyperTensor(table.data(), vs_, latents, 3, precisions_.softdeca);
}

// The networks' part of a preparation: hyper-tensors, stages and dynamics coefficients.
std::shared_ptr<Preparation> Avatar::prepare_networks(const prepare::ParameterState& params, const std::vector<float>& identity,
                                                      std::vector<float>& stages) const {
  auto prep = std::make_shared<Preparation>();
  prep->dt = dt_;
  prep->identity = identity;
  for (const int model : {kSoftDeca, kSparse}) {
    const bool sparse = model == kSparse;
    if (!model_->has(sparse)) continue;
    if (sparse) {  // the sparse model's hyper-tensor: per vertex
      const OnnxNetwork& hyper = *model_->hyper(true);
      std::vector<float> p(vs_ * hyper.spec().parameter_columns.size());
      params.vertex_matrix(hyper.spec().parameter_columns, p.data());
      prep->vertex_l = hyper_tensor(hyper, p, identity, vs_, 3, precisions_.sparse);
    } else {
      stages = prepare_softdeca_stages(params, identity, *prep);
    }
    // Dynamics coefficients per skin vertex.
    const OnnxNetwork& dyn = *model_->dynamics(sparse);
    const auto& dcols = dyn.spec().parameter_columns;
    std::vector<float> pv(vs_ * dcols.size());
    params.vertex_matrix(dcols, pv.data());
    DynamicsCoefficients& c = prep->dynamics[model];
    c.alpha.resize(vs_);
    c.beta.resize(vs_);
    c.gamma.resize(vs_);
    dyn.run({pv.data(), identity.data()}, {c.alpha.data(), c.beta.data(), c.gamma.data()}, 1);
    c.check(m_, dyn.spec().key.c_str());
  }
  return prep;
}

// SoftDECA's static frame at rest for other parameters than the preparation's: its stages
// alone (no dynamics, no sparse model).
std::vector<float> Avatar::softdeca_rest(const prepare::ParameterState& params, const std::vector<float>& identity) const {
  Preparation stages;
  stages.dt = dt_;
  prepare_softdeca_stages(params, identity, stages);
  return softdeca_rest(stages);
}

std::vector<float> Avatar::softdeca_rest(const Preparation& prep) const {
  const std::vector<float> weights(bundle::kBlendshapeCount, 0.0f);
  std::vector<float> z(static_cast<std::size_t>(m_.latent)), out(vs_ * 3);
  model_->encoder(false)->run({weights.data()}, {z.data()}, 1);
  const bool gate_open = m_.rest_gate > 0;  // M1: the networks' w-independent part as an expression has it
  if (gate_open) z.back() = 1.0f;
  if (prep.face_l.zero()) {
    std::copy(neutral_.begin(), neutral_.begin() + static_cast<std::ptrdiff_t>(vs_ * 3), out.begin());
  } else {
    std::vector<float> rhs(vs_ * kernels::kRhsStride, 0.0f);
    kernels::dg_rhs(prep.face_l, prep.dt->faces(), z.data(), neutral_.data(), 0, prep.face_l.blocks(), rhs.data());
    std::vector<double> work(prep.dt->work_size());
    const float* parts[] = {rhs.data()};
    prep.dt->solve(parts, 1, neutral_.data(), work.data(), out.data());
  }
  if (!prep.vertex_stages.empty()) {  // the coefficients (z, c), as a frame's (encode_weights)
    std::vector<float> zc(stage_latents_ + residual_modes_);
    std::copy_n(z.begin(), stage_latents_, zc.begin());
    if (residual_modes_ > 0)
      model_->residual_coefficients()->run({weights.data(), prep.residual_condition.data()}, {zc.data() + stage_latents_}, 1);
    if (gate_open) zc.back() = 1.0f;  // the mean mode's coefficient: the gate too
    kernels::vertex_offsets(prep.vertex_stages, zc.data(), out.data(), 0, prep.vertex_stages.blocks(), out.data());
  }
  return out;
}

Avatar::RestCorrection Avatar::rest_correction(const prepare::ParameterState& params, const Preparation& prep,
                                               const std::vector<float>& identity, int& iterations) {
  if (!rest_physics_) {  // kept only once its defaults' solve succeeded
    auto physics = std::make_unique<prepare::RestPhysics>(*model_->rest_head(), m_, neutral_.data(), model_->skin_triangles(),
                                                 static_cast<int>(worker_.parts()));
    rest_physics0_ = physics->solve(prepare::ParameterState(m_, model_->skin_triangles(), geometry_.face_area));
    rest_physics_ = std::move(physics);
  }
  const sim::Positions physics = rest_physics_->solve(params);
  iterations = rest_physics_->iterations();
  RestCorrection r;
  r.offset.resize(vs_ * 3);
  const auto physics_change = [&](std::size_t v, std::size_t c) {
    const auto row = static_cast<Eigen::Index>(v), col = static_cast<Eigen::Index>(c);
    return physics(row, col) - rest_physics0_(row, col);
  };
  if (m_.rest_changes) {
    // Trained on S_t + Pd: the networks' response to p is what an expression adds on top of
    // the rest physics, so the frame gets the physics' change whole and keeps theirs.
    for (std::size_t v = 0; v < vs_; ++v)
      for (std::size_t c = 0; c < 3; ++c) r.offset[3 * v + c] = static_cast<float>(physics_change(v, c));
    if (!all_finite(r.offset.data(), r.offset.size()))
      throw Error(SOFTDECA_ERROR_NON_FINITE, "the physics at prepare produced a non-finite skin for these parameters");
    return r;
  }
  // Each distinct parameter set runs the networks once: p's own stages are the preparation's,
  // the defaults' are kept per identity, and p's rest-inert part is p itself when every
  // parameter p moves is rest-inert.
  if (rest_model0_.empty() || rest_model0_identity_ != identity) {
    rest_model0_ = softdeca_rest(prepare::ParameterState(m_, model_->skin_triangles(), geometry_.face_area), identity);
    rest_model0_identity_ = identity;
  }
  // The networks' own rest response to p, less their response to p's rest-inert parameters
  // alone: the physics says nothing about those at rest, so that part stays the networks'.
  const prepare::ParameterState inert_only = params.only(m_.rest_physics.inert_parameters);
  const std::vector<float> model = softdeca_rest(prep);
  std::optional<std::vector<float>> inert_rest;
  const std::vector<float>& model_inert = inert_only.at_defaults() ? rest_model0_
                                          : inert_only == params    ? model
                                                                    : inert_rest.emplace(softdeca_rest(inert_only, identity));
  // With a rest gate the networks add nothing at rest: the frame then gets the physics' change
  // whole, and the networks' own change (the gate open) is taken off as the gate opens.
  const bool gated = m_.rest_gate > 0;
  if (gated) r.gated.resize(vs_ * 3);
  for (std::size_t v = 0; v < vs_; ++v)
    for (std::size_t c = 0; c < 3; ++c) {
      const std::size_t i = 3 * v + c;
      const double model_change = double(model[i]) - double(model_inert[i]);
      r.offset[i] = static_cast<float>(gated ? physics_change(v, c) : physics_change(v, c) - model_change);
      if (gated) r.gated[i] = static_cast<float>(-model_change);
    }
  if (!all_finite(r.offset.data(), r.offset.size()) || !all_finite(r.gated.data(), r.gated.size()))
    throw Error(SOFTDECA_ERROR_NON_FINITE, "the physics at prepare produced a non-finite skin for these parameters");
  return r;
}

// The residual stage's prepare half: its condition and modes for these parameters.
std::vector<float> Avatar::prepare_residual(const prepare::ParameterState& params, Preparation& prep) const {
  const OnnxNetwork* net = model_->residual_condition();
  if (!net) return {};
  const auto& cols = net->spec().parameter_columns;
  std::vector<float> pv(vs_ * cols.size());
  params.vertex_matrix(cols, pv.data());
  const std::size_t k = static_cast<std::size_t>(m_.residual_modes);
  std::vector<float> condition(static_cast<std::size_t>(m_.residual_condition)), modes(vs_ * k * 3);
  net->run({pv.data()}, {condition.data(), modes.data()}, 1);
  if (!all_finite(condition.data(), condition.size()) || !all_finite(modes.data(), modes.size()))
    throw Error(SOFTDECA_ERROR_FORMAT, net->spec().key + " produced non-finite values for these parameters");
  prep.residual_condition = std::move(condition);
  return modes;
}

}  // namespace softdeca::runtime
