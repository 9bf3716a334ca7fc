#include "runtime/avatar.h"

#include "runtime/frame_guard.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "core/error.h"

namespace softdeca::runtime {

namespace {
using Clock = std::chrono::steady_clock;
double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

constexpr int kSoftDeca = 0, kSparse = 1;
constexpr float kWeightSlack = 0.01f;  // weights may overshoot [0, 1] by this much (clamped)

bool all_finite(const float* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}
}  // namespace

// A hypernetwork's L(p, h) for n elements of the given width, checked and stored.
HyperTensor Avatar::hyper_tensor(const OnnxNetwork& net, const std::vector<float>& parameters,
                                 const std::vector<float>& identity, std::size_t n, std::size_t width) const {
  std::vector<float> l(n * static_cast<std::size_t>(m_.latent) * width);
  net.run({parameters.data(), identity.data()}, {l.data()}, 1);
  if (!all_finite(l.data(), l.size()))
    throw Error(SOFTDECA_ERROR_FORMAT, net.spec().key + " produced non-finite values for these parameters");
  return HyperTensor(l.data(), n, m_.latent, static_cast<int>(width), precision_);
}

std::size_t Preparation::bytes() const {
  return face_l.bytes() + vertex_l.bytes() + softdeca_vertex_l.bytes() + residual_modes.bytes() +
         residual_condition.size() * 4 + dynamics[0].bytes() + dynamics[1].bytes() + identity.size() * 4 +
         rest_offset.size() * 4;
}

Avatar::Avatar(std::shared_ptr<const Model> model, const AvatarDesc& d)
    : model_(std::move(model)),
      m_(model_->manifest()),
      vh_(static_cast<std::size_t>(m_.head_vertices)),
      vs_(static_cast<std::size_t>(m_.skin_vertices)),
      nf_(static_cast<std::size_t>(m_.skin_triangles)),
      precision_(d.precision),
      neutral_(d.neutral, d.neutral + vh_ * 3),
      triangles_(d.triangles, d.triangles + d.triangle_count * 3),
      geometry_(SkinGeometry::measure(neutral_.data(), vs_, model_->skin_triangles())),
      blendshapes_(d.blendshapes ? Blendshapes(d.blendshapes, d.blendshape_count, vh_, d.threads) : Blendshapes()),
      worker_(d.threads),
      params_(m_, model_->skin_triangles(), geometry_.face_area),
      weights_(kBlendshapeCount),
      z_(static_cast<std::size_t>(m_.latent)),
      offsets_(3 * m_.landmarks.size()),
      head_(vh_ * 3),
      static_(vs_ * 3),
      residual_condition_(static_cast<std::size_t>(m_.residual_condition)),
      residual_coefficients_(static_cast<std::size_t>(m_.residual_modes)),
      solve_work_(vs_ * 4),
      dynamics_(vs_),
      normals_(triangles_, vh_) {
  for (std::size_t p = 0; p < worker_.parts(); ++p) {
    rhs_.emplace_back(vs_ * 3);
    rhs_parts_.push_back(rhs_.back().data());
  }
  // Landmarks on the avatar's neutral skin.
  const auto& tri = model_->skin_triangles();
  for (const LandmarkSpec& l : m_.landmarks) {
    landmark_arkit_.push_back(l.arkit_vertex);
    for (int c = 0; c < 3; ++c) {
      double p = 0;
      for (int k = 0; k < 3; ++k)
        p += l.bary[k] * neutral_[3 * static_cast<std::size_t>(tri[3 * static_cast<std::size_t>(l.triangle) + static_cast<std::size_t>(k)]) +
                                 static_cast<std::size_t>(c)];
      neutral_landmarks_.push_back(p);
    }
  }
  const auto& bones = model_->non_skin_bones();
  for (std::size_t i = 0; i < bones.size(); ++i)
    (bones[i] ? jaw_vertices_ : cranium_vertices_).push_back(static_cast<int>(vs_ + i));
  identity_ = model_->encode_identity(neutral_.data());
  if (model_->has(false)) f_w_ = model_->encoder(false)->bind({weights_.data()}, {z_.data()}, 1);
  if (model_->has(true)) f_l_ = model_->encoder(true)->bind({offsets_.data()}, {z_.data()}, 1);
  if (const OnnxNetwork* r = model_->residual_coefficients())
    f_r_w_ = r->bind({weights_.data(), residual_condition_.data()}, {residual_coefficients_.data()}, 1);
  stats_.threads = worker_.parts();
}

Avatar::~Avatar() = default;

// ---- parameters and identity ------------------------------------------------------------------

void Avatar::set_parameter(int index, double value) {
  std::lock_guard<std::mutex> lock(params_mutex_);
  params_.set_global(index, value);
}

void Avatar::set_parameter_faces(int index, const float* values, std::size_t count) {
  std::lock_guard<std::mutex> lock(params_mutex_);
  params_.set_faces(index, values, count);
}

void Avatar::set_parameter_vertices(int index, const float* values, std::size_t count) {
  std::lock_guard<std::mutex> lock(params_mutex_);
  params_.set_vertices(index, values, count);
}

void Avatar::reset_parameters() {
  std::lock_guard<std::mutex> lock(params_mutex_);
  params_.reset();
}

void Avatar::get_parameter(int index, double* value, bool* localised) const {
  std::lock_guard<std::mutex> lock(params_mutex_);
  require(index >= 0 && static_cast<std::size_t>(index) < m_.parameters.size(), "parameter index out of range");
  if (value) *value = params_.global(index);
  if (localised) *localised = params_.kind(index) != ParameterState::Kind::Global;
}

void Avatar::set_identity(const float* values, std::size_t count) {
  require_not_null(values, "identity");
  require(count == static_cast<std::size_t>(m_.identity), "identity has " + std::to_string(count) +
                                                              " values, the bundle's identity size is " +
                                                              std::to_string(m_.identity));
  require_finite(values, count, "identity");
  std::lock_guard<std::mutex> lock(params_mutex_);
  identity_.assign(values, values + count);
}

void Avatar::get_identity(float* out, std::size_t capacity) const {
  require_not_null(out, "out_identity");
  require(capacity >= static_cast<std::size_t>(m_.identity),
          "capacity " + std::to_string(capacity) + " is below the identity size " + std::to_string(m_.identity),
          SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  std::lock_guard<std::mutex> lock(params_mutex_);
  std::copy(identity_.begin(), identity_.end(), out);
}

// ---- prepare ---------------------------------------------------------------------------------

void Avatar::prepare() {
  std::lock_guard<std::mutex> prepare_lock(prepare_mutex_);
  const auto t0 = Clock::now();
  std::vector<float> identity;
  std::unique_ptr<ParameterState> params;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params = std::make_unique<ParameterState>(params_);
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
  std::shared_ptr<Preparation> prep = prepare_networks(*params, identity);
  const double networks_ms = ms(n0, Clock::now());
  // The physics at prepare: nothing to correct at the defaults (c(p0) = 0).
  double physics_ms = 0;
  int physics_iterations = 0;
  if (model_->rest_head() && model_->has(false) && !params->at_defaults()) {
    const auto r0 = Clock::now();
    prep->rest_offset = rest_offset(*params, *prep, identity, physics_iterations);
    physics_ms = ms(r0, Clock::now());
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

// The networks' part of a preparation: hyper-tensors, stages and dynamics coefficients.
std::shared_ptr<Preparation> Avatar::prepare_networks(const ParameterState& params,
                                                      const std::vector<float>& identity) const {
  auto prep = std::make_shared<Preparation>();
  prep->dt = dt_;
  prep->identity = identity;
  for (const int model : {kSoftDeca, kSparse}) {
    const bool sparse = model == kSparse;
    if (!model_->has(sparse)) continue;
    // Hyper-tensor: per face (SoftDECA) or per vertex (sparse).
    const OnnxNetwork& hyper = *model_->hyper(sparse);
    const auto& cols = hyper.spec().parameter_columns;
    const std::size_t n = sparse ? vs_ : nf_, width = sparse ? 3 : 9;
    std::vector<float> p(n * cols.size());
    if (sparse) params.vertex_matrix(cols, p.data());
    else params.face_matrix(cols, p.data());
    (sparse ? prep->vertex_l : prep->face_l) = hyper_tensor(hyper, p, identity, n, width);
    if (const OnnxNetwork* stage = sparse ? nullptr : model_->softdeca_vertex_stage()) {
      std::vector<float> pv(vs_ * stage->spec().parameter_columns.size());
      params.vertex_matrix(stage->spec().parameter_columns, pv.data());
      prep->softdeca_vertex_l = hyper_tensor(*stage, pv, identity, vs_, 3);
    }
    if (!sparse) prepare_residual(params, *prep);
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

std::vector<float> Avatar::softdeca_rest(const Preparation& prep) const {
  const std::vector<float> weights(kBlendshapeCount, 0.0f);
  std::vector<float> z(static_cast<std::size_t>(m_.latent)), out(vs_ * 3);
  model_->encoder(false)->run({weights.data()}, {z.data()}, 1);
  if (prep.face_l.zero()) {
    std::copy(neutral_.begin(), neutral_.begin() + static_cast<std::ptrdiff_t>(vs_ * 3), out.begin());
  } else {
    std::vector<float> rhs(vs_ * 3, 0.0f);
    dg_rhs(prep.face_l, prep.dt->faces(), z.data(), neutral_.data(), 0, prep.face_l.blocks(), rhs.data());
    std::vector<double> work(prep.dt->work_size());
    const float* parts[] = {rhs.data()};
    prep.dt->solve(parts, 1, neutral_.data(), work.data(), out.data());
  }
  if (!prep.softdeca_vertex_l.empty())
    vertex_offsets(prep.softdeca_vertex_l, z.data(), out.data(), 0, prep.softdeca_vertex_l.blocks(), out.data());
  if (!prep.residual_modes.empty()) {
    std::vector<float> c(static_cast<std::size_t>(m_.residual_modes));
    model_->residual_coefficients()->run({weights.data(), prep.residual_condition.data()}, {c.data()}, 1);
    vertex_offsets(prep.residual_modes, c.data(), out.data(), 0, prep.residual_modes.blocks(), out.data());
  }
  return out;
}

std::vector<float> Avatar::rest_offset(const ParameterState& params, const Preparation& prep,
                                       const std::vector<float>& identity, int& iterations) {
  if (!rest_physics_) {  // kept only once its defaults' solve succeeded
    auto physics = std::make_unique<RestPhysics>(*model_->rest_head(), m_, neutral_.data(), model_->skin_triangles(),
                                                 static_cast<int>(worker_.parts()));
    rest_physics0_ = physics->solve(ParameterState(m_, model_->skin_triangles(), geometry_.face_area));
    rest_physics_ = std::move(physics);
  }
  if (rest_model0_.empty() || rest_model0_identity_ != identity) {
    const ParameterState defaults(m_, model_->skin_triangles(), geometry_.face_area);
    rest_model0_ = softdeca_rest(*prepare_networks(defaults, identity));
    rest_model0_identity_ = identity;
  }
  const sim::Positions physics = rest_physics_->solve(params);
  iterations = rest_physics_->iterations();
  // The networks' own rest response to p, less their response to p's rest-inert parameters
  // alone: the physics says nothing about those at rest, so that part stays the networks'.
  const ParameterState inert_only = params.only(m_.rest_physics.inert_parameters);
  const std::vector<float> model = softdeca_rest(prep);
  const std::vector<float> model_inert =
      inert_only.at_defaults() ? rest_model0_ : softdeca_rest(*prepare_networks(inert_only, identity));
  std::vector<float> offset(vs_ * 3);
  for (std::size_t v = 0; v < vs_; ++v)
    for (std::size_t c = 0; c < 3; ++c) {
      const std::size_t i = 3 * v + c;
      const auto row = static_cast<Eigen::Index>(v), col = static_cast<Eigen::Index>(c);
      offset[i] = static_cast<float>((physics(row, col) - rest_physics0_(row, col)) - (double(model[i]) - double(model_inert[i])));
    }
  if (!all_finite(offset.data(), offset.size()))
    throw Error(SOFTDECA_ERROR_NON_FINITE, "the physics at prepare produced a non-finite skin for these parameters");
  return offset;
}

// The residual stage's prepare half: its condition and modes for these parameters.
void Avatar::prepare_residual(const ParameterState& params, Preparation& prep) const {
  const OnnxNetwork* net = model_->residual_condition();
  if (!net) return;
  const auto& cols = net->spec().parameter_columns;
  std::vector<float> pv(vs_ * cols.size());
  params.vertex_matrix(cols, pv.data());
  const std::size_t k = static_cast<std::size_t>(m_.residual_modes);
  std::vector<float> condition(static_cast<std::size_t>(m_.residual_condition)), modes(vs_ * k * 3);
  net->run({pv.data()}, {condition.data(), modes.data()}, 1);
  if (!all_finite(condition.data(), condition.size()) || !all_finite(modes.data(), modes.size()))
    throw Error(SOFTDECA_ERROR_FORMAT, net->spec().key + " produced non-finite values for these parameters");
  prep.residual_condition = std::move(condition);
  prep.residual_modes = HyperTensor(modes.data(), vs_, m_.residual_modes, 3, precision_);
}

std::shared_ptr<const Preparation> Avatar::current() const {
  std::lock_guard<std::mutex> lock(current_mutex_);
  return current_;
}

// ---- frames ----------------------------------------------------------------------------------

void check_output_capacity(const Output& out, std::size_t vertices) {
  require_not_null(out.vertices, "output.vertices");
  expect(out.vertex_capacity >= vertices, [&] {
    return "output.vertex_capacity " + std::to_string(out.vertex_capacity) + " is below the avatar's " +
           std::to_string(vertices) + " vertices";
  }, SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  if (out.normals)
    expect(out.normal_capacity >= vertices, [&] {
      return "output.normal_capacity " + std::to_string(out.normal_capacity) + " is below the avatar's " +
             std::to_string(vertices) + " vertices";
    }, SOFTDECA_ERROR_BUFFER_TOO_SMALL);
}

void Avatar::read_weights(const float* weights, std::size_t count) {
  require_not_null(weights, "weights");
  expect(count == kBlendshapeCount,
         [&] { return "expected 52 blendshape weights (canonical ARKit order), got " + std::to_string(count); });
  require_finite(weights, count, "weights");
  for (std::size_t i = 0; i < count; ++i) {
    expect(weights[i] >= -kWeightSlack && weights[i] <= 1 + kWeightSlack, [&] {
      return "weights[" + std::to_string(i) + "] (" + stream::blendshape_name(i) + ") = " + std::to_string(weights[i]) +
             " is outside [0, 1]";
    });
    weights_[i] = std::min(1.0f, std::max(0.0f, weights[i]));
  }
}

void Avatar::softdeca_frame(const Preparation& prep, AvatarStats& st) {
  auto t = Clock::now();
  model_->encoder(false)->run(f_w_);
  auto t1 = Clock::now();
  st.encoder_ms = ms(t, t1);
  if (prep.face_l.zero()) {
    // Every G_f is I: DT(S_t, I) = S_t + K^-1 0 = S_t exactly, so neither the right-hand side
    // nor the solve is needed (a model started in closed form has no DT correction yet).
    std::memcpy(static_.data(), head_.data(), vs_ * 3 * sizeof(float));
    add_vertex_stages(prep, st, Clock::now());
    return;
  }
  const std::size_t blocks = prep.face_l.blocks();
  auto pass = [&](std::size_t part, std::size_t n_parts) {
    float* rhs = rhs_[part].data();
    std::memset(rhs, 0, vs_ * 3 * sizeof(float));
    dg_rhs(prep.face_l, prep.dt->faces(), z_.data(), head_.data(), blocks * part / n_parts, blocks * (part + 1) / n_parts,
           rhs);
  };
  worker_.run(pass);
  auto t2 = Clock::now();
  st.hyper_ms = ms(t1, t2);
  for (int phase = 0; phase < DeformationTransfer::kPhases; ++phase) {
    auto solve = [&](std::size_t part, std::size_t) {
      prep.dt->solve_phase(phase, part, rhs_parts_.data(), rhs_parts_.size(), head_.data(), solve_work_.data(),
                           static_.data());
    };
    if (phase == 1) solve(0, worker_.parts());  // the serial top part: on this thread, no hand-off
    else worker_.run(solve);
  }
  auto t3 = Clock::now();
  st.solve_ms = ms(t2, t3);
  add_vertex_stages(prep, st, t3);
}

void Avatar::add_vertex_stages(const Preparation& prep, AvatarStats& st, Clock::time_point since) {
  // The vertex stage on top of DT's result, in place: static_ += z . L_v.
  if (!prep.softdeca_vertex_l.empty()) add_vertex_offsets(prep.softdeca_vertex_l, z_.data());
  // The residual stage: its coefficients from w and the preparation's condition, then
  // static_ += c . modes.
  if (!prep.residual_modes.empty()) {
    std::memcpy(residual_condition_.data(), prep.residual_condition.data(), prep.residual_condition.size() * sizeof(float));
    model_->residual_coefficients()->run(f_r_w_);
    add_vertex_offsets(prep.residual_modes, residual_coefficients_.data());
  }
  // The physics at prepare's correction (empty at the defaults).
  if (!prep.rest_offset.empty()) {
    float* x = static_.data();
    for (std::size_t i = 0; i < prep.rest_offset.size(); ++i) x[i] += prep.rest_offset[i];
  }
  st.hyper_ms += ms(since, Clock::now());
}

void Avatar::add_vertex_offsets(const HyperTensor& modes, const float* coefficients) {
  const std::size_t blocks = modes.blocks();
  auto pass = [&](std::size_t part, std::size_t parts) {
    vertex_offsets(modes, coefficients, static_.data(), blocks * part / parts, blocks * (part + 1) / parts,
                   static_.data());
  };
  worker_.run(pass);
}

void Avatar::write_rigid_non_skin(const float* skin, float* head) const {
  for (const int v : cranium_vertices_) std::memcpy(head + 3 * v, neutral_.data() + 3 * v, 3 * sizeof(float));
  if (jaw_vertices_.empty()) return;
  const Similarity r = fit_similarity(neutral_.data(), m_.jaw_anchors.data(), skin, m_.jaw_anchors.data(),
                                      m_.jaw_anchors.size(), false);
  for (const int v : jaw_vertices_) {
    const float* n = neutral_.data() + 3 * v;
    for (int i = 0; i < 3; ++i)
      head[3 * v + i] = static_cast<float>(r.rotation[3 * i] * n[0] + r.rotation[3 * i + 1] * n[1] + r.rotation[3 * i + 2] * n[2] +
                                           r.translation[i]);
  }
}

void Avatar::compute_normals(const float* head, float* normals) {
  auto faces = [&](std::size_t part, std::size_t parts) { normals_.faces(head, part, parts); };
  worker_.run(faces);
  auto vertices = [&](std::size_t part, std::size_t parts) { normals_.vertices(normals, part, parts); };
  worker_.run(vertices);
}

void Avatar::finish(const Preparation& prep, int model, const float* skin, const float* non_skin, const Output& out,
                    AvatarStats& st) {
  auto t = Clock::now();
  if (reset_requested_.exchange(false)) dynamics_.invalidate();
  const float* result = skin;
  if (dynamics_enabled_.load()) {
    const DynamicsCoefficients& c = prep.dynamics[model];
    auto pass = [&](std::size_t part, std::size_t parts) {
      dynamics_.step(c, model, skin, vs_ * part / parts, vs_ * (part + 1) / parts);
    };
    worker_.run(pass);
    result = dynamics_.next();
  }
  if (!all_finite(result, vs_ * 3))
    throw Error(SOFTDECA_ERROR_NON_FINITE, "the model produced a non-finite vertex; the previous output stays valid");
  if (dynamics_enabled_.load()) dynamics_.commit(model);
  else dynamics_.invalidate();
  auto t1 = Clock::now();
  st.dynamics_ms = ms(t, t1);
  float* head = out.vertices;
  std::memcpy(head, result, vs_ * 3 * sizeof(float));
  if (non_skin) std::memcpy(head + vs_ * 3, non_skin, (vh_ - vs_) * 3 * sizeof(float));
  else write_rigid_non_skin(result, head);
  auto t2 = Clock::now();
  st.output_ms = ms(t1, t2);
  if (out.normals) compute_normals(head, out.normals);
  st.normals_ms = ms(t2, Clock::now());
  st.generation = prep.generation;
}

namespace {
void require_model(const Model& m, bool sparse) {
  expect(m.has(sparse), [&] { return std::string("the bundle has no ") + (sparse ? "SparseSoftDECA" : "SoftDECA") + " model"; });
}
std::shared_ptr<const Preparation> require_prepared(std::shared_ptr<const Preparation> p) {
  if (!p) throw Error(SOFTDECA_ERROR_NOT_READY, "the avatar is not prepared yet: call softdeca_avatar_prepare first");
  return p;
}
}  // namespace

void Avatar::evaluate_weights(const float* weights, std::size_t count, const Output& out) {
  FrameGuard guard(busy_);
  const auto t0 = Clock::now();
  require_model(*model_, false);
  check_output_capacity(out, vh_);
  expect(!blendshapes_.empty(),
         [] { return std::string("the avatar was created without blendshapes: use softdeca_avatar_evaluate_surface"); });
  read_weights(weights, count);
  const auto prep = require_prepared(current());
  AvatarStats st;
  auto blend = [&](std::size_t part, std::size_t) { blendshapes_.blend(weights_.data(), neutral_.data(), head_.data(), part); };
  worker_.run(blend);
  st.blend_ms = ms(t0, Clock::now());
  softdeca_frame(*prep, st);
  finish(*prep, kSoftDeca, static_.data(), head_.data() + vs_ * 3, out, st);
  st.frame_ms = ms(t0, Clock::now());
  record(st);
}

void Avatar::evaluate_surface(const float* weights, std::size_t count, const float* surface, std::size_t vertices,
                              const Output& out) {
  FrameGuard guard(busy_);
  const auto t0 = Clock::now();
  require_model(*model_, false);
  check_output_capacity(out, vh_);
  read_weights(weights, count);
  require_not_null(surface, "surface");
  expect(vertices == vs_ || vertices == vh_, [&] {
    return "surface has " + std::to_string(vertices) + " vertices; expected the skin's " + std::to_string(vs_) +
           " or the head's " + std::to_string(vh_);
  });
  require_finite(surface, vertices * 3, "surface");
  const auto prep = require_prepared(current());
  std::memcpy(head_.data(), surface, vertices * 3 * sizeof(float));
  AvatarStats st;
  st.blend_ms = ms(t0, Clock::now());
  softdeca_frame(*prep, st);
  finish(*prep, kSoftDeca, static_.data(), vertices == vh_ ? head_.data() + vs_ * 3 : nullptr, out, st);
  st.frame_ms = ms(t0, Clock::now());
  record(st);
}

const float* Avatar::select_landmarks(const float* points, std::size_t count, const char* what) const {
  require_not_null(points, what);
  const std::size_t k = m_.landmarks.size(), a = static_cast<std::size_t>(m_.arkit_vertex_count);
  expect(count == k || count == a, [&] {
    return std::string(what) + " has " + std::to_string(count) + " points; expected the " + std::to_string(k) +
           " landmarks or the " + std::to_string(a) + " vertices of ARKit's face mesh";
  });
  require_finite(points, count * 3, what);
  return points;
}

void Avatar::calibrate_landmarks(const float* points, std::size_t count) {
  FrameGuard guard(busy_);
  select_landmarks(points, count, "points");
  const std::size_t k = m_.landmarks.size();
  const bool full = count != k;
  std::vector<double> user(3 * k);
  for (std::size_t i = 0; i < k; ++i)
    for (int c = 0; c < 3; ++c)
      user[3 * i + c] = points[3 * (full ? static_cast<std::size_t>(landmark_arkit_[i]) : i) + static_cast<std::size_t>(c)];
  double centroid[3] = {0, 0, 0}, spread = 0;
  for (std::size_t i = 0; i < k; ++i)
    for (int c = 0; c < 3; ++c) centroid[c] += user[3 * i + static_cast<std::size_t>(c)] / static_cast<double>(k);
  for (std::size_t i = 0; i < k; ++i)
    for (int c = 0; c < 3; ++c) spread += std::pow(user[3 * i + static_cast<std::size_t>(c)] - centroid[c], 2) / static_cast<double>(k);
  require(spread > 1e-6, "the calibration landmarks are degenerate (they span less than a millimetre)");
  const Similarity s = fit_similarity(user.data(), neutral_landmarks_.data(), k, true);
  require(std::isfinite(s.scale) && s.scale > 0, "the calibration landmarks give no usable similarity");
  user_neutral_ = std::move(user);
  calibration_ = s;
  calibrated_ = true;
}

void Avatar::clear_calibration() {
  FrameGuard guard(busy_);
  calibrated_ = false;
}

void Avatar::evaluate_landmarks(const float* points, std::size_t count, const Output& out) {
  FrameGuard guard(busy_);
  const auto t0 = Clock::now();
  require_model(*model_, true);
  check_output_capacity(out, vh_);
  select_landmarks(points, count, "points");
  const auto prep = require_prepared(current());
  AvatarStats st;
  // Retarget: offsets from the user's neutral mapped by the calibration similarity, or (not
  // calibrated) the points taken as the avatar's own landmarks.
  const std::size_t k = m_.landmarks.size();
  const bool full = count != k;
  for (std::size_t i = 0; i < k; ++i) {
    const float* p = points + 3 * (full ? static_cast<std::size_t>(landmark_arkit_[i]) : i);
    double d[3];
    for (int c = 0; c < 3; ++c)
      d[c] = calibrated_ ? p[c] - user_neutral_[3 * i + static_cast<std::size_t>(c)]
                         : p[c] - neutral_landmarks_[3 * i + static_cast<std::size_t>(c)];
    for (int c = 0; c < 3; ++c) {
      double o = d[c];
      if (calibrated_)
        o = calibration_.scale * (calibration_.rotation[3 * c] * d[0] + calibration_.rotation[3 * c + 1] * d[1] +
                                  calibration_.rotation[3 * c + 2] * d[2]);
      offsets_[3 * i + static_cast<std::size_t>(c)] = static_cast<float>(o);
    }
  }
  auto t1 = Clock::now();
  model_->encoder(true)->run(f_l_);
  auto t2 = Clock::now();
  st.encoder_ms = ms(t1, t2);
  const std::size_t blocks = prep->vertex_l.blocks();
  auto pass = [&](std::size_t part, std::size_t parts) {
    vertex_offsets(prep->vertex_l, z_.data(), neutral_.data(), blocks * part / parts, blocks * (part + 1) / parts,
                   static_.data());
  };
  worker_.run(pass);
  st.hyper_ms = ms(t2, Clock::now());
  finish(*prep, kSparse, static_.data(), nullptr, out, st);
  st.frame_ms = ms(t0, Clock::now());
  record(st);
}

void Avatar::evaluate_linear(const float* weights, std::size_t count, const Output& out) {
  FrameGuard guard(busy_);
  const auto t0 = Clock::now();
  check_output_capacity(out, vh_);
  expect(!blendshapes_.empty(), [] { return std::string("the avatar was created without blendshapes"); });
  read_weights(weights, count);
  AvatarStats st;
  auto blend = [&](std::size_t part, std::size_t) { blendshapes_.blend(weights_.data(), neutral_.data(), out.vertices, part); };
  worker_.run(blend);
  const auto t1 = Clock::now();
  st.blend_ms = ms(t0, t1);
  if (out.normals) compute_normals(out.vertices, out.normals);
  st.normals_ms = ms(t1, Clock::now());
  st.frame_ms = ms(t0, Clock::now());
  record(st);
}

void Avatar::record(AvatarStats st) {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  st.frames = stats_.frames + 1;
  st.preparations = stats_.preparations;
  st.threads = stats_.threads;
  if (st.generation == 0) st.generation = stats_.generation;
  st.prepare_ms = stats_.prepare_ms;
  st.prepare_networks_ms = stats_.prepare_networks_ms;
  st.prepare_physics_ms = stats_.prepare_physics_ms;
  st.physics_iterations = stats_.physics_iterations;
  st.factorisation_ms = stats_.factorisation_ms;
  stats_ = st;
}

AvatarStats Avatar::stats() const {
  AvatarStats s;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    s = stats_;
  }
  std::size_t bytes = neutral_.size() * 4 + triangles_.size() * 4 + blendshapes_.bytes() + normals_.bytes() +
                      dynamics_.bytes() + head_.bytes() + static_.bytes() + rhs_.size() * rhs_[0].bytes() +
                      solve_work_.bytes() + geometry_.face_area.size() * 8 * 5;
  if (const auto p = current()) bytes += p->bytes() + (p->dt ? p->dt->bytes() : 0);
  s.memory_bytes = bytes;
  return s;
}

}  // namespace softdeca::runtime
