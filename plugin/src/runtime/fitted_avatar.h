// Every avatar at run time, whichever mesh the user has: SoftDECA and SparseSoftDECA run on the
// registered template (an Avatar in the template's topology, made from the fit), and every frame
// returns the avatar's own vertices: its own linear blend plus the models' correction carried
// through the fit's embedding (SparseSoftDECA: its whole deformation). Vertices the embedding
// does not hold move exactly as the avatar's rig moves them.
//
// A mesh in the template's topology is the identity fit: the registered template is the mesh
// itself and the embedding the identity, so the core's frame is the avatar's, with nothing to
// carry (the template path, at the core's own cost). Both run one frame path, which applies the
// avatar's FitTransfer (runtime/fit_transfer.h) step by step; the C ABI's handle holds one of
// these whatever the mesh, and calls it alike.
#pragma once

#include <atomic>
#include <memory>

#include "fit/avatar_fit.h"
#include "runtime/avatar.h"
#include "runtime/fit_transfer.h"

namespace softdeca::runtime {

// What a fit needs of a model's bundle; Error(INVALID_ARGUMENT) when it has no template head.
fit::TemplateData fit_template(const Model& m);

struct FittedAvatarDesc {
  const fit::AvatarFit* fit = nullptr;
  const fit::AvatarMesh* mesh = nullptr;  // the mesh the fit was made for (checked by its hash)
  std::size_t threads = 1;
  Precisions precisions;
};

class FittedAvatar {
 public:
  // The user's mesh through its fit.
  FittedAvatar(std::shared_ptr<const Model> model, const FittedAvatarDesc& desc);
  // A mesh in the template's topology: the identity fit.
  FittedAvatar(std::shared_ptr<const Model> model, const AvatarDesc& desc);

  // The registered template's avatar: parameters, identity, prepare, dynamics, calibration.
  Avatar& core() { return *core_; }
  const Avatar& core() const { return *core_; }

  // Maps over the avatar's own triangles or vertices, carried to the template's skin vertices.
  void set_parameter_faces(int index, const float* values, std::size_t count);
  void set_parameter_vertices(int index, const float* values, std::size_t count);

  // `codes`: the core's z and c as a batch computed them (runtime/frame_batch.h; null: none).
  void evaluate_weights(const float* weights, std::size_t count, const Output& out, const FrameCodes* codes = nullptr);
  void evaluate_landmarks(const float* points, std::size_t count, const Output& out);
  void evaluate_linear(const float* weights, std::size_t count, const Output& out);
  // A surface in the template's topology: the identity fit's only (another mesh's correction
  // comes from its weights or landmarks).
  void evaluate_surface(const float* weights, std::size_t count, const float* surface, std::size_t vertices, const Output& out);

  // What the avatar holds besides its core (nothing for the identity fit).
  std::size_t bytes() const { return transfer_->bytes(); }

 private:
  std::unique_ptr<Avatar> core_;
  std::unique_ptr<FitTransfer> transfer_;
  std::atomic<bool> busy_{false};  // one frame thread at a time (the transfer's buffers)
};

}  // namespace softdeca::runtime
