// The core avatar's frames (avatar.h): SoftDECA from weights or a surface, SparseSoftDECA from
// landmarks, the linear blend; each ends in the dynamics, the output and the normals.
#include "runtime/avatar.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "core/error.h"
#include "runtime/avatar_detail.h"
#include "runtime/frame_guard.h"

namespace softdeca::runtime {

using namespace avatar_detail;

namespace {
constexpr float kWeightSlack = 0.01f;  // weights may overshoot [0, 1] by this much (clamped)

// A frame's result, checked before anything of it reaches an output.
void require_finite_frame(const float* v, std::size_t n) {
  if (!all_finite(v, n))
    throw Error(SOFTDECA_ERROR_NON_FINITE, "the model produced a non-finite vertex; the previous output stays valid");
}

// A per-frame network's coefficients, checked before a table is contracted with them: an int8
// table's kernels quantise the coefficients to integers, where a NaN or an infinity becomes a
// finite, wrong frame that the frame's own check cannot see.
void require_finite_coefficients(const float* c, std::size_t n) {
  if (!all_finite(c, n))
    throw Error(SOFTDECA_ERROR_NON_FINITE, "the model produced a non-finite coefficient; the previous output stays valid");
}
}  // namespace

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

void Avatar::check_weights(const float* weights, std::size_t count, float* out) {
  require_not_null(weights, "weights");
  expect(count == bundle::kBlendshapeCount,
         [&] { return "expected 52 blendshape weights (canonical ARKit order), got " + std::to_string(count); });
  require_finite(weights, count, "weights");
  for (std::size_t i = 0; i < count; ++i) {
    expect(weights[i] >= -kWeightSlack && weights[i] <= 1 + kWeightSlack, [&] {
      return "weights[" + std::to_string(i) + "] (" + stream::blendshape_name(i) + ") = " + std::to_string(weights[i]) +
             " is outside [0, 1]";
    });
    out[i] = std::min(1.0f, std::max(0.0f, weights[i]));
  }
}

void Avatar::read_weights(const float* weights, std::size_t count) { check_weights(weights, count, weights_.data()); }

void Avatar::encode_weights(const Preparation& prep, AvatarStats& st, const FrameCodes* codes) {
  auto t = Clock::now();
  if (codes) std::memcpy(z_.data(), codes->z, z_.size() * sizeof(float));
  else model_->encoder(false)->run(f_w_);
  auto t1 = Clock::now();
  st.encoder_ms += ms(t, t1) + (codes ? codes->network_ms : 0.0);
  require_finite_coefficients(z_.data(), z_.size());
  if (stage_latents_ > 0)  // no vertex stages: no table, and memcpy takes no null pointer
    std::memcpy(stage_coefficients_.data(), z_.data(), stage_latents_ * sizeof(float));
  if (residual_modes_ > 0) {  // c from w and the preparation's condition
    float* c = stage_coefficients_.data() + stage_latents_;
    if (codes) {
      std::memcpy(c, codes->c, residual_modes_ * sizeof(float));
    } else {
      std::memcpy(residual_condition_.data(), prep.residual_condition.data(), prep.residual_condition.size() * sizeof(float));
      model_->residual_coefficients()->run(f_r_w_);  // after z's copy: only its own part to check
    }
    require_finite_coefficients(c, residual_modes_);
  }
  st.hyper_ms += ms(t1, Clock::now());
}

void Avatar::softdeca_frame(const Preparation& prep, AvatarStats& st) {
  if (prep.face_l.zero()) {
    // Every G_f is I: DT(S_t, I) = S_t + K^-1 0 = S_t exactly, so neither the right-hand side
    // nor the solve is needed (a model started in closed form has no DT correction yet): the
    // vertex stages start from the blend itself.
    add_vertex_stages(prep, head_.data(), static_.data(), st);
    return;
  }
  auto t1 = Clock::now();
  const std::size_t blocks = prep.face_l.blocks();
  auto pass = [&](std::size_t part, std::size_t n_parts) {
    float* rhs = rhs_[part].data();
    std::memset(rhs, 0, vs_ * kernels::kRhsStride * sizeof(float));
    kernels::dg_rhs(prep.face_l, prep.dt->faces(), z_.data(), head_.data(), blocks * part / n_parts,
                    blocks * (part + 1) / n_parts, rhs);
  };
  worker_.run(pass);
  auto t2 = Clock::now();
  st.hyper_ms += ms(t1, t2);
  for (int phase = 0; phase < DeformationTransfer::kPhases; ++phase) {
    auto solve = [&](std::size_t part, std::size_t) {
      prep.dt->solve_phase(phase, part, rhs_parts_.data(), rhs_parts_.size(), head_.data(), solve_work_.data(),
                           static_.data());
    };
    if (phase == 1) solve(0, worker_.parts());  // the serial top part: on this thread, no hand-off
    else worker_.run(solve);
  }
  st.solve_ms = ms(t2, Clock::now());
  add_vertex_stages(prep, static_.data(), static_.data(), st);
}

void Avatar::add_vertex_stages(const Preparation& prep, const float* base, float* out, AvatarStats& st) {
  const auto t = Clock::now();
  // The physics at prepare's correction (empty at the defaults) joins the same pass.
  const float* rest = prep.rest_offset.empty() ? nullptr : prep.rest_offset.data();
  if (!prep.vertex_stages.empty()) {
    const std::size_t blocks = prep.vertex_stages.blocks();
    auto pass = [&](std::size_t part, std::size_t parts) {
      kernels::vertex_offsets(prep.vertex_stages, stage_coefficients_.data(), base, rest, blocks * part / parts,
                              blocks * (part + 1) / parts, out);
    };
    worker_.run(pass);
  } else {  // no stages (a bundle before them): base and the physics' correction alone
    for (std::size_t i = 0; i < vs_ * 3; ++i) out[i] = (base ? base[i] : 0.0f) + (rest ? rest[i] : 0.0f);
  }
  st.hyper_ms += ms(t, Clock::now());
}

bool Avatar::in_place(const Preparation& prep, bool dynamics) const {
  if (dynamics || !prep.face_l.zero()) return false;
  // No value the frame forms exceeds the neutral's largest coordinate plus what the blend and
  // the stages can add at most (each |coefficient| times its table's largest entry): float
  // sums of terms bounded so far below float's range cannot overflow, and every input is
  // finite (a non-finite one makes the bound infinite or NaN). 1e12 m: no head comes near it,
  // and its square (the normals' cross products) is still far inside float's range.
  constexpr double kLimit = 1e12;
  double reach = double(neutral_peak_) + blendshapes_.reach(weights_.data()) + double(prep.rest_offset_peak);
  for (int k = 0; k < prep.vertex_stages.latent(); ++k)
    reach += std::fabs(double(stage_coefficients_[static_cast<std::size_t>(k)])) * prep.vertex_stages.peak(k);
  return reach < kLimit;  // false for NaN
}

void Avatar::write_rigid_non_skin(const float* skin, float* head) const {
  for (const int v : cranium_vertices_) std::memcpy(head + 3 * v, neutral_.data() + 3 * v, 3 * sizeof(float));
  if (jaw_vertices_.empty()) return;
  const geometry::Similarity r = geometry::fit_similarity(neutral_.data(), m_.jaw_anchors.data(), skin, m_.jaw_anchors.data(),
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

const float* Avatar::settle(const Preparation& prep, int model, const float* skin, bool dynamics, AvatarStats& st) {
  auto t = Clock::now();
  if (reset_requested_.exchange(false)) dynamics_.invalidate();
  const float* result = skin;
  if (dynamics) {
    const DynamicsCoefficients& c = prep.dynamics[model];
    auto pass = [&](std::size_t part, std::size_t parts) {
      dynamics_.step(c, model, skin, vs_ * part / parts, vs_ * (part + 1) / parts);
    };
    worker_.run(pass);
    result = dynamics_.next();
  }
  require_finite_frame(result, vs_ * 3);
  if (dynamics) dynamics_.commit(model);
  else dynamics_.invalidate();
  st.dynamics_ms = ms(t, Clock::now());
  return result;
}

void Avatar::settle_static() {
  reset_requested_.store(false);
  dynamics_.invalidate();
}

void Avatar::finish(const Preparation& prep, int model, const float* skin, const float* non_skin, bool dynamics,
                    const Output& out, AvatarStats& st) {
  const float* result = settle(prep, model, skin, dynamics, st);
  auto t1 = Clock::now();
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

std::shared_ptr<const Preparation> Avatar::prepared() const { return require_prepared(current()); }

void Avatar::evaluate_weights(const float* weights, std::size_t count, const Output& out, const FrameCodes* codes) {
  FrameGuard guard(busy_);
  const auto t0 = Clock::now();
  require_model(*model_, false);
  check_output_capacity(out, vh_);
  expect(!blendshapes_.empty(),
         [] { return std::string("the avatar was created without blendshapes: use softdeca_avatar_evaluate_surface"); });
  read_weights(weights, count);
  const auto prep = codes ? codes->prep : require_prepared(current());
  AvatarStats st;
  st.blend_ms = ms(t0, Clock::now());
  encode_weights(*prep, st, codes);
  const bool dynamics = dynamics_enabled_.load();
  const bool direct = in_place(*prep, dynamics);
  // In place, the frame is the linear blend straight into the output, its skin then corrected
  // where it lies; otherwise the blend goes to head_ and the tail checks the skin before it
  // writes the output.
  float* blend_into = direct ? out.vertices : head_.data();
  const auto tb = Clock::now();
  auto blend = [&](std::size_t part, std::size_t) { blendshapes_.blend(weights_.data(), neutral_.data(), blend_into, part); };
  worker_.run(blend);
  st.blend_ms += ms(tb, Clock::now());
  if (direct) {
    add_vertex_stages(*prep, out.vertices, out.vertices, st);
    settle_static();
    const auto t = Clock::now();
    if (out.normals) compute_normals(out.vertices, out.normals);
    st.normals_ms = ms(t, Clock::now());
    st.generation = prep->generation;
  } else {
    softdeca_frame(*prep, st);
    finish(*prep, kSoftDeca, static_.data(), head_.data() + vs_ * 3, dynamics, out, st);
  }
  st.frame_ms = ms(t0, Clock::now());
  st.frame_bytes = softdeca_bytes(*prep, 0, dynamics, out.normals != nullptr);
  record(st);
}

void Avatar::evaluate_carried(const float* weights, std::size_t count, float* carried, const FrameCodes* codes) {
  FrameGuard guard(busy_);
  const auto t0 = Clock::now();
  require_model(*model_, false);
  expect(!blendshapes_.empty() && carry_ != nullptr,
         [] { return std::string("evaluate_carried needs an avatar made with blendshapes and a carry map"); });
  read_weights(weights, count);
  const auto prep = codes ? codes->prep : require_prepared(current());
  AvatarStats st;
  encode_weights(*prep, st, codes);
  const bool dynamics = dynamics_enabled_.load();
  const bool blended = dynamics || !prep->face_l.zero();
  const std::size_t n = carry_->size();
  if (!blended) {
    // The frame's skin is S_t + the stages' offsets (DT(S_t, I) = S_t, no dynamics): its
    // correction is the offsets whatever S_t is, and carried, the carried table's contraction.
    const auto t = Clock::now();
    const float* rest = prep->carried_rest.empty() ? nullptr : prep->carried_rest.data();
    if (!prep->carried_stages.empty()) {
      const std::size_t blocks = prep->carried_stages.blocks();
      auto pass = [&](std::size_t part, std::size_t parts) {
        kernels::vertex_offsets(prep->carried_stages, stage_coefficients_.data(), nullptr, rest, blocks * part / parts,
                                blocks * (part + 1) / parts, carried);
      };
      worker_.run(pass);
    } else {  // no stages: the physics at prepare's correction alone
      for (std::size_t i = 0; i < n * 3; ++i) carried[i] = rest ? rest[i] : 0.0f;
    }
    st.hyper_ms += ms(t, Clock::now());
    const auto t1 = Clock::now();
    require_finite_frame(carried, n * 3);
    settle_static();
    st.dynamics_ms = ms(t1, Clock::now());
  } else {  // the template's whole frame, less its blend, carried
    const auto tb = Clock::now();
    auto blend = [&](std::size_t part, std::size_t) { blendshapes_.blend(weights_.data(), neutral_.data(), head_.data(), part); };
    worker_.run(blend);
    st.blend_ms = ms(tb, Clock::now());
    softdeca_frame(*prep, st);
    const float* result = settle(*prep, kSoftDeca, static_.data(), dynamics, st);
    const auto t = Clock::now();
    for (std::size_t i = 0; i < vs_ * 3; ++i) static_[i] = result[i] - head_[i];
    carry_->carry(static_.data(), carried);
    st.output_ms = ms(t, Clock::now());
  }
  st.generation = prep->generation;
  st.frame_ms = ms(t0, Clock::now());
  st.frame_bytes = carried_bytes(*prep, blended, dynamics);
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
  encode_weights(*prep, st, nullptr);
  softdeca_frame(*prep, st);
  const bool dynamics = dynamics_enabled_.load();
  finish(*prep, kSoftDeca, static_.data(), vertices == vh_ ? head_.data() + vs_ * 3 : nullptr, dynamics, out, st);
  st.frame_ms = ms(t0, Clock::now());
  st.frame_bytes = softdeca_bytes(*prep, vertices, dynamics, out.normals != nullptr);
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
  const geometry::Similarity s = geometry::fit_similarity(user.data(), neutral_landmarks_.data(), k, true);
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
  require_finite_coefficients(z_.data(), z_.size());
  const std::size_t blocks = prep->vertex_l.blocks();
  auto pass = [&](std::size_t part, std::size_t parts) {
    kernels::vertex_offsets(prep->vertex_l, z_.data(), neutral_.data(), blocks * part / parts, blocks * (part + 1) / parts,
                   static_.data());
  };
  worker_.run(pass);
  st.hyper_ms = ms(t2, Clock::now());
  const bool dynamics = dynamics_enabled_.load();
  finish(*prep, kSparse, static_.data(), nullptr, dynamics, out, st);
  st.frame_ms = ms(t0, Clock::now());
  st.frame_bytes = sparse_bytes(*prep, dynamics, out.normals != nullptr);
  record(st);
}

void Avatar::read_frame_weights(const float* weights, std::size_t count) {
  FrameGuard guard(busy_);
  read_weights(weights, count);
  record(AvatarStats{});
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
  st.frame_bytes = linear_bytes(out.normals != nullptr);
  record(st);
}

}  // namespace softdeca::runtime
