// The least bytes each kind of frame moves (FrameBytes, avatar.h), summed from the sizes of what
// the frame's stages read and write, along the same paths as avatar_evaluate.cpp.
#include "runtime/avatar.h"
#include "runtime/avatar_detail.h"

namespace softdeca::runtime {

using namespace avatar_detail;

namespace {
constexpr std::uint64_t kVertexBytes = 3 * sizeof(float);

std::uint64_t weight_bytes(const OnnxNetwork* network) { return network ? network->weight_bytes() : 0; }
}  // namespace

void Avatar::add_tail_bytes(const Preparation& prep, int model, bool dynamics, bool rigid_non_skin, bool normals,
                            FrameBytes& b) const {
  // The coefficients, the two previous states read and the new one written.
  if (dynamics) b.dynamics = prep.dynamics[model].bytes() + 3 * vs_ * kVertexBytes;
  b.output = vh_ * kVertexBytes + (rigid_non_skin ? (vh_ - vs_) * kVertexBytes : 0);
  if (normals) b.normals = normals_.topology_bytes() + vh_ * kVertexBytes;
}

FrameBytes Avatar::softdeca_bytes(const Preparation& prep, std::size_t surface, bool dynamics, bool normals) const {
  FrameBytes b;
  b.blend = surface ? surface * kVertexBytes : vh_ * kVertexBytes + blendshapes_.bytes_read(weights_.data());
  b.encoder = weight_bytes(model_->encoder(false));
  if (!prep.face_l.zero()) {  // the DT path (softdeca_frame)
    b.hyper = prep.face_l.stored_bytes() + prep.dt->face_bytes();
    b.solve = prep.dt->solve_bytes();
  }
  b.hyper += prep.vertex_stages.stored_bytes() + weight_bytes(model_->residual_coefficients()) +
             prep.rest_offset.size() * sizeof(float);
  add_tail_bytes(prep, kSoftDeca, dynamics, surface == vs_, normals, b);
  return b;
}

FrameBytes Avatar::carried_bytes(const Preparation& prep, bool blended, bool dynamics) const {
  // The template's whole frame where it ran, else the carried table in place of the stages'
  // and no blend; then the carry map (where the frame carries its skin) and the carried
  // correction written instead of the head, with no normals.
  FrameBytes b = softdeca_bytes(prep, 0, dynamics, false);
  if (blended) {
    b.output = carry_->bytes() + carry_->size() * kVertexBytes;
  } else {
    b.blend = 0;
    b.hyper = weight_bytes(model_->residual_coefficients()) + prep.carried_stages.stored_bytes() +
              prep.carried_rest.size() * sizeof(float);
    b.output = carry_->size() * kVertexBytes;
  }
  return b;
}

FrameBytes Avatar::sparse_bytes(const Preparation& prep, bool dynamics, bool normals) const {
  FrameBytes b;
  b.encoder = weight_bytes(model_->encoder(true));
  b.hyper = prep.vertex_l.stored_bytes() + vs_ * kVertexBytes;  // L and the neutral skin it offsets
  add_tail_bytes(prep, kSparse, dynamics, true, normals, b);
  return b;
}

FrameBytes Avatar::linear_bytes(bool normals) const {
  FrameBytes b;
  // The neutral read, the moved shapes' deltas, the head written (straight into the output).
  b.blend = 2 * vh_ * kVertexBytes + blendshapes_.bytes_read(weights_.data());
  if (normals) b.normals = normals_.topology_bytes() + vh_ * kVertexBytes;
  return b;
}

}  // namespace softdeca::runtime
