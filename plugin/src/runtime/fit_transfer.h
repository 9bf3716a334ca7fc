// How a frame of the registered template (the core Avatar of a FittedAvatar) becomes a frame of
// the avatar's own mesh, one step at a time, so that every avatar runs the same frame path:
//
//   a frame of weights: softdeca(core, weights); finish()
//   a frame of landmarks: core frame into core_output(out); rest(); carry(neutral); finish()
//   a linear frame alone: linear(core, weights); finish()
//
// Through a fit (embedding_transfer) the avatar's own rig gives the linear part, and the core's
// correction (of its linear blend, or its whole deformation of the neutral) is carried through
// the fit's embedding. A mesh in the template's topology is the identity fit
// (identity_transfer): the core writes straight into the caller's output and every step leaves
// it as it is, so the template path costs what the core costs. The steps are per frame (a
// virtual call each); their loops over vertices are inside.
#pragma once

#include <cstddef>
#include <memory>

#include "fit/avatar_fit.h"
#include "runtime/avatar.h"
#include "runtime/carry_map.h"

namespace softdeca::runtime {

class FitTransfer {
 public:
  virtual ~FitTransfer() = default;

  // Where the core writes a frame for `out`: `out` itself, or the registered template's buffer
  // once `out` is checked to hold the avatar's vertices (Error(BUFFER_TOO_SMALL) otherwise).
  virtual Output core_output(const Output& out) = 0;
  // Where the core writes a frame of a surface in the template's topology: the identity fit's
  // `out`; Error(INVALID_ARGUMENT) through a fit, whose correction comes from weights or landmarks.
  virtual Output surface_output(const Output& out) = 0;

  // A SoftDECA frame of 52 weights into out: the identity fit's is the core's own frame;
  // through a fit, the avatar's own linear blend of the weights as the core read them (checked
  // and clamped) plus the core's correction of its linear blend carried onto the avatar's
  // vertices (Avatar::evaluate_carried), so the registered template is blended only where the
  // correction needs it (the dynamics on, a DT stage).
  // `codes`: the core's z and c as a batch computed them (null: the core runs its networks).
  virtual void softdeca(Avatar& core, const float* weights, std::size_t count, const Output& out,
                        const FrameCodes* codes) = 0;
  // A frame of the linear blend alone: the core checks the weights and counts the frame, and
  // blends only where its head is the avatar's (the identity fit); through a fit the avatar's
  // own rig blends them, so the registered template is not blended for nothing.
  virtual void linear(Avatar& core, const float* weights, std::size_t count, const Output& out) = 0;
  // out = the avatar's own neutral.
  virtual void rest(const Output& out) = 0;
  // out += the core's last frame into core_output minus `base` (the registered template's skin
  // vertices x 3), carried onto the avatar's vertices.
  virtual void carry(const float* base, const Output& out) = 0;
  // The normals of out's vertices, when it asks for them.
  virtual void finish(const Output& out) = 0;

  // A parameter's map over the avatar's own triangles or vertices, given to the core over the
  // registered template's skin vertices.
  virtual void set_parameter_faces(Avatar& core, int index, const float* values, std::size_t count) = 0;
  virtual void set_parameter_vertices(Avatar& core, int index, const float* values, std::size_t count) = 0;

  // What the transfer holds (nothing for the identity fit).
  virtual std::size_t bytes() const = 0;
};

// The identity fit: the core's frames and maps are the avatar's.
std::unique_ptr<FitTransfer> identity_transfer();

// The avatar `mesh` through its fit `f` to the template `t`; `core_shapes` are the registered
// template's 52 shapes (fit::carried_shapes), which give the shapes the avatar's rig lacks;
// `carry`, the fit's carry map, which the core (made with it) shares.
std::unique_ptr<FitTransfer> embedding_transfer(const fit::TemplateData& t, const fit::AvatarMesh& mesh,
                                                const fit::AvatarFit& f, const float* core_shapes,
                                                std::shared_ptr<const CarryMap> carry);

}  // namespace softdeca::runtime
