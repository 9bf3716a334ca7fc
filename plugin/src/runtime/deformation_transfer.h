// Deformation transfer DT(S_t, G) (paper eq. 17), the formulation of docs/bundle.md and
// training/softdeca_train/models/dt.py: per-face gradients measured on the avatar's neutral
// (cotangent Poisson) plus a small mass-weighted pull toward S_t. The matrix depends only on the
// neutral, so it is assembled and factorised once per avatar; a frame is one right-hand side
// pass (hypertensor.h: dg_rhs) and one three-column solve: X = S_t + K^-1 r.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "geometry/sparse_ldlt.h"
#include "kernels/hypertensor.h"

namespace softdeca::runtime {

// Per-face and per-vertex measures of the avatar's neutral skin.
struct SkinGeometry {
  std::vector<double> face_area;    // a_f
  std::vector<double> metric;       // a_f W_f as (w00, w01, w11) per face
  std::vector<double> vertex_mass;  // m_v = sum a_f / 3

  // Throws Error(INVALID_ARGUMENT) for a skin triangle with (almost) no area.
  static SkinGeometry measure(const float* skin, std::size_t n_vertices, const std::vector<std::int32_t>& triangles);
};

class DeformationTransfer {
 public:
  // `parts`: threads that will run solve_phase.
  DeformationTransfer(const SkinGeometry& geometry, std::size_t n_vertices, const std::vector<std::int32_t>& triangles,
                      double regularisation, std::size_t parts = 1);

  const kernels::FaceBlocks& faces() const { return faces_; }
  // The faces in the order of faces(): element e of the per-face hyper-tensor is face
  // face_order()[e] (kernels::HyperTensor's `order`).
  const std::vector<std::int32_t>& face_order() const { return face_order_; }
  std::size_t vertices() const { return ldlt_.size(); }
  std::size_t bytes() const {
    return ldlt_.bytes() + faces_.corners.bytes() + faces_.coeff.bytes() + face_order_.size() * sizeof(std::int32_t);
  }
  std::size_t factor_nonzeros() const { return ldlt_.factor_nonzeros(); }
  // What a frame reads: the right-hand side's face blocks, and the factor in the solve.
  std::size_t face_bytes() const { return faces_.corners.bytes() + faces_.coeff.bytes(); }
  std::size_t solve_bytes() const { return ldlt_.solve_bytes(); }

  // out = skin + K^-1 (r[0] + ... + r[count-1]), each r V x 4 (kernels::dg_rhs). `work`:
  // work_size() doubles.
  std::size_t work_size() const { return ldlt_.work_size(); }
  void solve(const float* const* r, std::size_t count, const float* skin, double* work, float* out) const;
  // The same in SparseLdlt's phases (every part of phase p before phase p + 1).
  static constexpr int kPhases = geometry::SparseLdlt::kPhases;
  void solve_phase(int phase, std::size_t part, const float* const* r, std::size_t count, const float* skin, double* work,
                   float* out) const {
    ldlt_.solve_phase(phase, part, r, count, work, skin, out);
  }
  double serial_fraction() const { return ldlt_.serial_fraction(); }

 private:
  std::vector<std::int32_t> face_order_;
  kernels::FaceBlocks faces_;
  geometry::SparseLdlt ldlt_;
};

}  // namespace softdeca::runtime
