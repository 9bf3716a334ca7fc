#include "runtime/fitted_avatar.h"

#include <Eigen/LU>
#include <string>
#include <vector>

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
  require(f.registered.size() == t.head_vertices * 3, "the fit's registered head does not match the bundle's template");

  // The registered template as an avatar of the template's topology, with the carried shapes.
  const std::vector<float> shapes = fit::carried_shapes(t, a, f);
  auto carry = std::make_shared<const CarryMap>(f.embedding, t.skin_triangles, f.placement.linear.inverse().cast<float>());
  AvatarDesc core;
  core.neutral = f.registered.data();
  core.vertex_count = t.head_vertices;
  core.triangles = t.skin_triangles;
  core.triangle_count = t.skin_triangle_count;
  core.blendshapes = shapes.data();
  core.blendshape_count = bundle::kBlendshapeCount;
  core.threads = d.threads;
  core.precisions = d.precisions;
  core.carry = carry;
  // The identity code of the template identity closest to the avatar: the encoder reads a head
  // of the template's own making, not the registration's (a few millimetres of sliding along
  // the skin changes its code far more than the head's shape does).
  const std::vector<float> identity =
      f.identity.empty() ? std::vector<float>{} : model->encode_identity(fit::identity_skin(t, f).data());
  core_ = std::make_unique<Avatar>(std::move(model), core);
  if (!identity.empty()) core_->set_identity(identity.data(), identity.size());

  transfer_ = embedding_transfer(t, a, f, shapes.data(), std::move(carry));
}

FittedAvatar::FittedAvatar(std::shared_ptr<const Model> model, const AvatarDesc& d)
    : core_(std::make_unique<Avatar>(std::move(model), d)), transfer_(identity_transfer()) {}

// One frame path for every avatar: the core's frame, then the transfer's steps onto the mesh.
void FittedAvatar::evaluate_weights(const float* weights, std::size_t count, const Output& out, const FrameCodes* codes) {
  FrameGuard guard(busy_);
  transfer_->softdeca(*core_, weights, count, out, codes);
  transfer_->finish(out);
}

void FittedAvatar::evaluate_landmarks(const float* points, std::size_t count, const Output& out) {
  FrameGuard guard(busy_);
  core_->evaluate_landmarks(points, count, transfer_->core_output(out));
  transfer_->rest(out);
  transfer_->carry(core_->neutral().data(), out);  // the whole deformation of the registered template
  transfer_->finish(out);
}

void FittedAvatar::evaluate_linear(const float* weights, std::size_t count, const Output& out) {
  FrameGuard guard(busy_);
  transfer_->linear(*core_, weights, count, out);
  transfer_->finish(out);
}

void FittedAvatar::evaluate_surface(const float* weights, std::size_t count, const float* surface, std::size_t vertices,
                                    const Output& out) {
  const Output target = transfer_->surface_output(out);  // refused through a fit before anything else
  FrameGuard guard(busy_);
  core_->evaluate_surface(weights, count, surface, vertices, target);
}

void FittedAvatar::set_parameter_vertices(int index, const float* values, std::size_t count) {
  transfer_->set_parameter_vertices(*core_, index, values, count);
}

void FittedAvatar::set_parameter_faces(int index, const float* values, std::size_t count) {
  transfer_->set_parameter_faces(*core_, index, values, count);
}

}  // namespace softdeca::runtime
