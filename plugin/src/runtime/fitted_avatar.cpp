#include "runtime/fitted_avatar.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/error.h"
#include "fit/mesh_hash.h"
#include "runtime/frame_guard.h"

namespace softdeca::runtime {

fit::TemplateData fit_template(const Model& m) {
  const bundle::TemplateHead* th = m.template_head();
  expect(th != nullptr, [] {
    return std::string("the bundle has no template head (format version 5): fitting an avatar needs one");
  });
  const bundle::Manifest& mf = m.manifest();
  fit::TemplateData t;
  t.head_neutral = th->neutral.data();
  t.head_vertices = static_cast<std::size_t>(mf.head_vertices);
  t.skin_vertices = static_cast<std::size_t>(mf.skin_vertices);
  t.shapes = th->shapes.data();
  t.moves = th->moves;
  t.identity_modes = th->identity_modes.data();
  t.identity_count = th->identity_count;
  t.skin_triangles = m.skin_triangles().data();
  t.skin_triangle_count = m.skin_triangles().size() / 3;
  for (const bundle::LandmarkSpec& l : mf.landmarks) {
    t.landmark_triangle.push_back(l.triangle);
    t.landmark_bary.push_back({l.bary[0], l.bary[1], l.bary[2]});
  }
  return t;
}

FittedAvatar::FittedAvatar(std::shared_ptr<const Model> model, const FittedAvatarDesc& d) {
  require(d.fit != nullptr && d.mesh != nullptr, "a fitted avatar needs its fit and its mesh");
  const fit::AvatarFit& f = *d.fit;
  const fit::AvatarMesh& a = *d.mesh;
  const fit::TemplateData t = fit_template(*model);
  require(a.vertex_count == f.vertex_count && a.triangle_count == f.triangle_count,
          "the mesh has " + std::to_string(a.vertex_count) + " vertices and " + std::to_string(a.triangle_count) +
              " triangles; the fit was made for " + std::to_string(f.vertex_count) + " and " +
              std::to_string(f.triangle_count));
  if (fit::mesh_sha256(a.neutral, a.vertex_count, a.triangles, a.triangle_count) != f.mesh_sha256)
    throw Error(SOFTDECA_ERROR_FORMAT, "the mesh is not the one the fit was made for (its neutral or triangles changed): fit it again");
  n_ = a.vertex_count;
  vs_ = t.skin_vertices;
  vh_ = t.head_vertices;
  require(f.registered.size() == vh_ * 3, "the fit's registered head does not match the bundle's template");

  // The registered template as an avatar of the template's topology, with the carried shapes.
  const std::vector<float> shapes = fit::carried_shapes(t, a, f);
  AvatarDesc core;
  core.neutral = f.registered.data();
  core.vertex_count = vh_;
  core.triangles = t.skin_triangles;
  core.triangle_count = t.skin_triangle_count;
  core.blendshapes = shapes.data();
  core.blendshape_count = bundle::kBlendshapeCount;
  core.threads = d.threads;
  core.precision = d.precision;
  // The identity code of the template identity closest to the avatar: the encoder reads a head
  // of the template's own making, not the registration's (a few millimetres of sliding along
  // the skin changes its code far more than the head's shape does).
  const std::vector<float> identity =
      f.identity.empty() ? std::vector<float>{} : model->encode_identity(fit::identity_skin(t, f).data());
  core_ = std::make_unique<Avatar>(std::move(model), core);
  if (!identity.empty()) core_->set_identity(identity.data(), identity.size());

  neutral_.assign(a.neutral, a.neutral + n_ * 3);
  triangles_.assign(a.triangles, a.triangles + a.triangle_count * 3);
  registered_skin_.assign(f.registered.begin(), f.registered.begin() + static_cast<std::ptrdiff_t>(vs_ * 3));
  embedding_ = f.embedding;
  skin_triangles_.assign(t.skin_triangles, t.skin_triangles + t.skin_triangle_count * 3);
  to_avatar_ = f.placement.linear.inverse().cast<float>();
  // The avatar's own shapes; a shape its rig lacks is the template's, carried back onto the
  // avatar's face through the embedding, so a rig without some (or any) shapes animates fully.
  std::vector<float> own(bundle::kBlendshapeCount * n_ * 3, 0.0f);
  for (std::size_t k = 0; k < static_cast<std::size_t>(bundle::kBlendshapeCount); ++k) {
    if (a.deltas[k]) std::memcpy(own.data() + k * n_ * 3, a.deltas[k], n_ * 3 * sizeof(float));
    else if (f.origin[k] == fit::ShapeOrigin::Template) add_carried(shapes.data() + k * vh_ * 3, own.data() + k * n_ * 3);
  }
  blendshapes_ = Blendshapes(own.data(), bundle::kBlendshapeCount, n_, 1);
  source_ = f.source;
  head_out_.resize(vh_ * 3);
  field_.resize(vs_ * 3);
  weights_.resize(bundle::kBlendshapeCount);
  normals_ = geometry::Normals(triangles_, n_);
}

FittedAvatar::FittedAvatar(std::shared_ptr<const Model> model, const AvatarDesc& d)
    : core_(std::make_unique<Avatar>(std::move(model), d)), identity_(true), n_(d.vertex_count) {}

std::size_t FittedAvatar::bytes() const {
  return (neutral_.size() + registered_skin_.size() + head_out_.size() + field_.size()) * 4 + triangles_.size() * 4 +
         blendshapes_.bytes() + normals_.bytes() + embedding_.size() * 28 + source_.corners.size() * 4 +
         source_.bary.size() * 4 + source_.weight.size() * 4 + skin_triangles_.size() * 4;
}

Output FittedAvatar::core_output() {
  Output inner;
  inner.vertices = head_out_.data();
  inner.vertex_capacity = vh_;
  return inner;
}

void FittedAvatar::own_blend(const float* weights, float* out) {
  for (std::size_t i = 0; i < static_cast<std::size_t>(bundle::kBlendshapeCount); ++i) weights_[i] = std::min(1.0f, std::max(0.0f, weights[i]));
  blendshapes_.blend(weights_.data(), neutral_.data(), out, 0);
}

void FittedAvatar::add_carried(const float* field, float* out) const {
  const std::size_t ne = embedding_.size();
  for (std::size_t e = 0; e < ne; ++e) {
    const std::int32_t* tri = skin_triangles_.data() + 3 * static_cast<std::size_t>(embedding_.triangle[e]);
    const float* b = embedding_.bary.data() + 3 * e;
    Eigen::Vector3f d = Eigen::Vector3f::Zero();
    for (int k = 0; k < 3; ++k) d += b[k] * Eigen::Map<const Eigen::Vector3f>(field + 3 * static_cast<std::size_t>(tri[k]));
    Eigen::Map<Eigen::Vector3f>(out + 3 * static_cast<std::size_t>(embedding_.vertex[e])) += embedding_.weight[e] * (to_avatar_ * d);
  }
}

void FittedAvatar::finish(const Output& out) {
  if (!out.normals) return;
  normals_.faces(out.vertices, 0, 1);
  normals_.vertices(out.normals, 0, 1);
}

void FittedAvatar::evaluate_weights(const float* weights, std::size_t count, const Output& out) {
  if (identity_) return core_->evaluate_weights(weights, count, out);
  FrameGuard guard(busy_);
  check_output_capacity(out, n_);
  core_->evaluate_weights(weights, count, core_output());  // checks the weights
  const float* lin = core_->linear_skin();
  for (std::size_t i = 0; i < vs_ * 3; ++i) field_[i] = head_out_[i] - lin[i];
  own_blend(weights, out.vertices);
  add_carried(field_.data(), out.vertices);
  finish(out);
}

void FittedAvatar::evaluate_landmarks(const float* points, std::size_t count, const Output& out) {
  if (identity_) return core_->evaluate_landmarks(points, count, out);
  FrameGuard guard(busy_);
  check_output_capacity(out, n_);
  core_->evaluate_landmarks(points, count, core_output());
  for (std::size_t i = 0; i < vs_ * 3; ++i) field_[i] = head_out_[i] - registered_skin_[i];
  std::memcpy(out.vertices, neutral_.data(), n_ * 3 * sizeof(float));
  add_carried(field_.data(), out.vertices);
  finish(out);
}

void FittedAvatar::evaluate_linear(const float* weights, std::size_t count, const Output& out) {
  if (identity_) return core_->evaluate_linear(weights, count, out);
  FrameGuard guard(busy_);
  check_output_capacity(out, n_);
  core_->evaluate_linear(weights, count, core_output());  // checks the weights, counts the frame
  own_blend(weights, out.vertices);
  finish(out);
}

void FittedAvatar::evaluate_surface(const float* weights, std::size_t count, const float* surface, std::size_t vertices,
                                    const Output& out) {
  require(identity_, "evaluate_surface takes a surface in the template's topology: an avatar on its own mesh takes weights or "
                     "landmarks");
  core_->evaluate_surface(weights, count, surface, vertices, out);
}

void FittedAvatar::set_parameter_vertices(int index, const float* values, std::size_t count) {
  if (identity_) return core_->set_parameter_vertices(index, values, count);
  require_not_null(values, "values");
  expect(count == n_, [&] {
    return "a fitted avatar's vertex map has one value per avatar vertex (" + std::to_string(n_) + "), got " +
           std::to_string(count);
  });
  require_finite(values, count, "values");
  // Each template skin vertex reads the map where it reads the avatar's shapes.
  std::vector<float> skin(vs_);
  for (std::size_t v = 0; v < vs_; ++v) {
    double x = 0;
    for (std::size_t k = 0; k < 3; ++k)
      x += source_.bary[3 * v + k] * values[static_cast<std::size_t>(source_.corners[3 * v + k])];
    skin[v] = static_cast<float>(x);
  }
  core_->set_parameter_vertices(index, skin.data(), skin.size());
}

void FittedAvatar::set_parameter_faces(int index, const float* values, std::size_t count) {
  if (identity_) return core_->set_parameter_faces(index, values, count);
  require_not_null(values, "values");
  const std::size_t nt = triangles_.size() / 3;
  expect(count == nt, [&] {
    return "a fitted avatar's face map has one value per avatar triangle (" + std::to_string(nt) + "), got " +
           std::to_string(count);
  });
  require_finite(values, count, "values");
  // Face values to vertex values (mean of the incident faces), then as a vertex map.
  std::vector<double> sum(n_, 0.0);
  std::vector<int> uses(n_, 0);
  for (std::size_t f = 0; f < nt; ++f)
    for (std::size_t k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(triangles_[3 * f + k]);
      sum[v] += values[f];
      ++uses[v];
    }
  std::vector<float> vertex(n_);
  for (std::size_t v = 0; v < n_; ++v) vertex[v] = uses[v] ? static_cast<float>(sum[v] / uses[v]) : values[0];
  set_parameter_vertices(index, vertex.data(), vertex.size());
}

}  // namespace softdeca::runtime
