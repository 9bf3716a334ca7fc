// The hyper-tensor L(p, h) (paper eq. 18, 25), stored for the per-frame product z . L: elements
// (faces for SoftDECA, vertices for SparseSoftDECA) in blocks of 8, each block laid out
// [latent][width][8 lanes] so one SIMD lane is one element and z_k is a broadcast. The product
// is bound by the bytes it reads, so the storage is compact: binary16, or int8 with one scale
// per block and latent (a quarter of float); the error each adds is measured (docs/runtime.md).
// Int8 blocks pair the latents, [latent / 2][width][8 lanes][2] (the latent count padded to
// even with zeros), so that one pmaddwd multiplies two latents of 8 elements by (z_k, z_k+1)
// quantised to int16 and sums them exactly in int32.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/aligned.h"

namespace softdeca::kernels {

enum class Precision { Half, Float, Int8 };
constexpr std::size_t kLanes = 8;

class HyperTensor {
 public:
  HyperTensor() = default;
  // `source` is the network output, row-major [n][latent][width]; element e holds its row
  // order[e] where an order is given (the caller's arrangement of the elements), else row e.
  HyperTensor(const float* source, std::size_t n, int latent, int width, Precision precision,
              const std::int32_t* order = nullptr);

  bool empty() const { return n_ == 0; }
  // Every entry of the source was zero: the product z . L is zero for every z.
  bool zero() const { return zero_; }
  // The largest magnitude of latent k's stored entries (infinite where one overflowed binary16):
  // |(z . L)[e, c]| <= sum_k |z_k| peak(k) for every element and component.
  float peak(int k) const { return peaks_[static_cast<std::size_t>(k)]; }
  std::size_t elements() const { return n_; }
  std::size_t blocks() const { return (n_ + kLanes - 1) / kLanes; }
  int latent() const { return latent_; }
  int stored_latent() const { return precision_ == Precision::Int8 ? (latent_ + 1) / 2 * 2 : latent_; }
  int width() const { return width_; }
  Precision precision() const { return precision_; }
  std::size_t block_stride() const { return static_cast<std::size_t>(stored_latent()) * width_ * kLanes; }
  // Flat index of block b, latent k, component c, lane (element b * 8 + lane).
  std::size_t index(std::size_t b, int k, int c, std::size_t lane) const {
    if (precision_ == Precision::Int8)
      return b * block_stride() + (static_cast<std::size_t>(k / 2) * width_ + c) * 2 * kLanes + lane * 2 + k % 2;
    return b * block_stride() + (static_cast<std::size_t>(k) * width_ + c) * kLanes + lane;
  }
  const std::uint16_t* half_data() const { return half_.data(); }
  const float* float_data() const { return float_.data(); }
  const std::int8_t* int8_data() const { return int8_.data(); }
  const float* scales() const { return scales_.data(); }  // Int8: [block][latent]
  std::size_t bytes() const {
    return half_.allocated_bytes() + float_.allocated_bytes() + int8_.allocated_bytes() + scales_.allocated_bytes();
  }
  // What one product z . L reads: the stored entries (padding lanes included) and the scales.
  std::size_t stored_bytes() const { return half_.bytes() + float_.bytes() + int8_.bytes() + scales_.bytes(); }
  // Element e, latent k, component c (for tests and the error measurement).
  float at(std::size_t e, int k, int c) const;

 private:
  std::size_t n_ = 0;
  int latent_ = 0, width_ = 0;
  bool zero_ = false;
  Precision precision_ = Precision::Half;
  std::vector<float> peaks_;  // by latent
  AlignedArray<std::uint16_t> half_;
  AlignedArray<float> float_;
  AlignedArray<std::int8_t> int8_;
  AlignedArray<float> scales_;
};

// What the deformation-transfer right-hand side needs per skin triangle, in the same blocks and
// in the order of the tensor's elements: corners (i, j, k) and a_f W_f as (w00, w01, w11);
// padding lanes have zero coefficients.
struct FaceBlocks {
  std::size_t blocks = 0;
  AlignedArray<std::int32_t> corners;  // [blocks][3][8]
  AlignedArray<float> coeff;           // [blocks][3][8]
};

// Which kernel computes the products: Best (frames) picks the fastest this CPU has for the
// tensor's storage; the others exist so that tests can compare every kernel the CPU runs.
// Avx512Vnni serves int8 storage only (vpdpwssd); Neon is aarch64's (hypertensor_neon.h); a
// kernel the CPU lacks runs as Portable.
enum class Kernel { Best, Portable, Avx2, Avx512Vnni, Neon };
bool kernel_available(Kernel kernel);

// rhs (V x kRhsStride: x, y, z and a lane no kernel reads, accumulated) += sum over the faces of
// blocks [b0, b1) of
//   D_f a_f W_f ((G_f - I) E_f(S))^T   with   G_f - I = sum_k z_k L[f, k] (row-major 3x3).
// The fourth lane lets a vector kernel add a face's term to a corner in one 16-byte add.
constexpr std::size_t kRhsStride = 4;
void dg_rhs(const HyperTensor& L, const FaceBlocks& faces, const float* z, const float* skin, std::size_t b0,
            std::size_t b1, float* rhs, Kernel kernel = Kernel::Best);

// out[v] = base[v] + add[v] + lanes[c][l] for the elements of block b that exist (the vector
// kernels' write-out of one block's 3 components, stored lane by lane); base and add may be
// null (nothing added), and out may be base (in place).
inline void add_block_offsets(const float (&lanes)[3][kLanes], const HyperTensor& L, std::size_t b, const float* base,
                              const float* add, float* out) {
  const std::size_t end = L.elements() - b * kLanes < kLanes ? L.elements() - b * kLanes : kLanes;
  for (std::size_t l = 0; l < end; ++l) {
    const std::size_t v = (b * kLanes + l) * 3;
    for (std::size_t c = 0; c < 3; ++c) {
      float x = lanes[c][l];
      if (add) x += add[v + c];
      out[v + c] = base ? base[v + c] + x : x;
    }
  }
}

// out[v] = base[v] + add[v] + sum_k z_k L[v, k] for the vertices of blocks [b0, b1) (width-3
// tensor). base and add may be null (nothing added); out may be base (in place).
void vertex_offsets(const HyperTensor& L, const float* z, const float* base, const float* add, std::size_t b0,
                    std::size_t b1, float* out, Kernel kernel = Kernel::Best);
// The same without `add`.
inline void vertex_offsets(const HyperTensor& L, const float* z, const float* base, std::size_t b0, std::size_t b1,
                           float* out, Kernel kernel = Kernel::Best) {
  vertex_offsets(L, z, base, nullptr, b0, b1, out, kernel);
}

}  // namespace softdeca::kernels
