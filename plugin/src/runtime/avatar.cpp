#include "runtime/avatar.h"

#include <algorithm>
#include <string>

#include "core/error.h"
#include "runtime/peak_magnitude.h"

namespace softdeca::runtime {

// The avatar's state and staged inputs; prepare is avatar_prepare.cpp, the frames avatar_evaluate.cpp.

Avatar::Avatar(std::shared_ptr<const Model> model, const AvatarDesc& d)
    : model_(std::move(model)),
      m_(model_->manifest()),
      vh_(static_cast<std::size_t>(m_.head_vertices)),
      vs_(static_cast<std::size_t>(m_.skin_vertices)),
      nf_(static_cast<std::size_t>(m_.skin_triangles)),
      precisions_(d.precisions),
      neutral_(d.neutral, d.neutral + vh_ * 3),
      neutral_peak_(peak_magnitude(neutral_.data(), neutral_.size())),
      triangles_(d.triangles, d.triangles + d.triangle_count * 3),
      geometry_(SkinGeometry::measure(neutral_.data(), vs_, model_->skin_triangles())),
      blendshapes_(d.blendshapes ? Blendshapes(d.blendshapes, d.blendshape_count, vh_, d.threads) : Blendshapes()),
      worker_(d.threads),
      carry_(d.carry),
      params_(m_, model_->skin_triangles(), geometry_.face_area),
      weights_(bundle::kBlendshapeCount),
      z_(static_cast<std::size_t>(m_.latent)),
      offsets_(3 * m_.landmarks.size()),
      head_(vh_ * 3),
      static_(vs_ * 3),
      stage_latents_(model_->softdeca_vertex_stage() ? static_cast<std::size_t>(m_.latent) : 0),
      residual_modes_(model_->residual_condition() ? static_cast<std::size_t>(m_.residual_modes) : 0),
      stage_coefficients_(stage_latents_ + residual_modes_),
      residual_condition_(static_cast<std::size_t>(m_.residual_condition)),
      solve_work_(vs_ * 4),
      dynamics_(vs_),
      normals_(triangles_, vh_) {
  for (std::size_t p = 0; p < worker_.parts(); ++p) {
    rhs_.emplace_back(vs_ * kernels::kRhsStride);
    rhs_parts_.push_back(rhs_.back().data());
  }
  // Landmarks on the avatar's neutral skin.
  const auto& tri = model_->skin_triangles();
  for (const bundle::LandmarkSpec& l : m_.landmarks) {
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
    f_r_w_ = r->bind({weights_.data(), residual_condition_.data()}, {stage_coefficients_.data() + stage_latents_}, 1);
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
  if (localised) *localised = params_.kind(index) != prepare::ParameterState::Kind::Global;
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

std::shared_ptr<const Preparation> Avatar::current() const {
  std::lock_guard<std::mutex> lock(current_mutex_);
  return current_;
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
