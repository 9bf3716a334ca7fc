#include "kernels/hypertensor_neon.h"

#ifdef SOFTDECA_NEON

#include <arm_neon.h>

#include <algorithm>
#include <cstdint>

namespace softdeca::kernels::neon {

namespace {

// One block's 8 lanes (elements b * 8 .. b * 8 + 7) as two 4-lane registers.
struct Lanes {
  float32x4_t lo, hi;
};

template <Precision P>
inline Lanes load8(const HyperTensor& L, std::size_t at) {
  if constexpr (P == Precision::Half) {
    // vcvt_f32_f16 is exact (every binary16 is a binary32), as F16C's vcvtph2ps.
    const float16x8_t h = vreinterpretq_f16_u16(vld1q_u16(L.half_data() + at));
    return {vcvt_f32_f16(vget_low_f16(h)), vcvt_high_f32_f16(h)};
  } else {
    const float* p = L.float_data() + at;
    return {vld1q_f32(p), vld1q_f32(p + 4)};
  }
}

// out[c] = sum_k z_k L[b, k, c] for c < W, half or float storage: one fused multiply-add per
// latent in latent order, as the AVX2 kernel, so both give the same float results.
template <Precision P, int W>
inline void contract(const HyperTensor& L, const float* z, std::size_t b, Lanes* out) {
  const int K = L.latent();
  const std::size_t base = b * L.block_stride();
  for (int c = 0; c < W; ++c) out[c] = {vdupq_n_f32(0.0f), vdupq_n_f32(0.0f)};
  for (int k = 0; k < K; ++k) {
    const float32x4_t zk = vdupq_n_f32(z[k]);
    const std::size_t at = base + static_cast<std::size_t>(k) * W * kLanes;
#pragma GCC unroll 9
    for (int c = 0; c < W; ++c) {
      const Lanes v = load8<P>(L, at + static_cast<std::size_t>(c) * kLanes);
      out[c].lo = vfmaq_f32(out[c].lo, zk, v.lo);
      out[c].hi = vfmaq_f32(out[c].hi, zk, v.hi);
    }
  }
}

// Int8 storage, the AVX2 kernel's scheme (hypertensor.cpp): z_k s_{b,k} quantised to an int16
// pair (coarse step t = max |z_k s_{b,k}| / 32767, remainder step t / 32768), each multiplied
// with the int8 values and summed exactly in int32, then scaled by its step. Returns t, 0 when
// every coefficient is 0. Rounding to nearest even (vcvtnq) and saturating narrowing (vqmovn), as
// cvtps2dq and packssdw: the same integers as on x86-64.
inline float quantise_coefficients(const HyperTensor& L, const float* z, std::size_t b, std::int16_t* zq, std::int16_t* zr) {
  const int K = L.latent(), K8 = (K + 7) / 8 * 8;
  const float* s = L.scales() + b * static_cast<std::size_t>(K);
  alignas(16) float zs[kMaxInt8Latent];
  for (int k = 0; k < K; ++k) zs[k] = z[k] * s[k];
  for (int k = K; k < K8; ++k) zs[k] = 0.0f;
  float32x4_t peak4 = vdupq_n_f32(0.0f);
  for (int k = 0; k < K8; k += 4) peak4 = vmaxq_f32(peak4, vabsq_f32(vld1q_f32(zs + k)));
  const float peak = vmaxvq_f32(peak4);
  if (!(peak > 0.0f)) return 0.0f;
  const float32x4_t inv = vdupq_n_f32(32767.0f / peak), fine = vdupq_n_f32(32768.0f);
  for (int k = 0; k < K8; k += 4) {
    const float32x4_t x = vmulq_f32(vld1q_f32(zs + k), inv);
    const int32x4_t a = vcvtnq_s32_f32(x);
    // |x - round(x)| <= 1/2, so the remainder times 32768 fits int16
    const int32x4_t r = vcvtnq_s32_f32(vmulq_f32(vsubq_f32(x, vcvtq_f32_s32(a)), fine));
    vst1_s16(zq + k, vqmovn_s32(a));
    vst1_s16(zr + k, vqmovn_s32(r));
  }
  return peak / 32767.0f;
}

// acc (lanes 0-3, 4-7) += the int16 values of 8 lanes times z.
inline void mac(int32x4_t& lo, int32x4_t& hi, int16x8_t v, std::int16_t z) {
  lo = vmlal_n_s16(lo, vget_low_s16(v), z);
  hi = vmlal_high_n_s16(hi, v, z);
}

template <int W>
inline void contract_int8(const HyperTensor& L, const float* z, std::size_t b, Lanes* out) {
  alignas(16) std::int16_t zq[kMaxInt8Latent], zr[kMaxInt8Latent];
  const float t = quantise_coefficients(L, z, b, zq, zr);
  for (int c = 0; c < W; ++c) out[c] = {vdupq_n_f32(0.0f), vdupq_n_f32(0.0f)};
  if (t == 0.0f) return;
  int32x4_t coarse[W][2], rest[W][2];
  for (int c = 0; c < W; ++c) coarse[c][0] = coarse[c][1] = rest[c][0] = rest[c][1] = vdupq_n_s32(0);
  const std::int8_t* q = L.int8_data() + b * L.block_stride();
  const int pairs = (L.latent() + 1) / 2;  // an odd count's last pair: quantise_coefficients padded zeros
  for (int p = 0; p < pairs; ++p) {
    const std::int16_t z0 = zq[2 * p], z1 = zq[2 * p + 1], r0 = zr[2 * p], r1 = zr[2 * p + 1];
    const std::int8_t* qp = q + static_cast<std::size_t>(p) * W * 2 * kLanes;
#pragma GCC unroll 9
    for (int c = 0; c < W; ++c) {
      // The pair's 16 bytes interleave the latents per lane: vld2 splits them.
      const int8x8x2_t v = vld2_s8(qp + c * 2 * kLanes);
      const int16x8_t v0 = vmovl_s8(v.val[0]), v1 = vmovl_s8(v.val[1]);
      mac(coarse[c][0], coarse[c][1], v0, z0);
      mac(coarse[c][0], coarse[c][1], v1, z1);
      mac(rest[c][0], rest[c][1], v0, r0);
      mac(rest[c][0], rest[c][1], v1, r1);
    }
  }
  const float32x4_t step = vdupq_n_f32(t), fine = vdupq_n_f32(t / 32768.0f);
  for (int c = 0; c < W; ++c) {
    out[c].lo = vfmaq_f32(vmulq_f32(vcvtq_f32_s32(coarse[c][0]), step), vcvtq_f32_s32(rest[c][0]), fine);
    out[c].hi = vfmaq_f32(vmulq_f32(vcvtq_f32_s32(coarse[c][1]), step), vcvtq_f32_s32(rest[c][1]), fine);
  }
}

template <Precision P, int W>
inline void contract_any(const HyperTensor& L, const float* z, std::size_t b, Lanes* out) {
  if constexpr (P == Precision::Int8) contract_int8<W>(L, z, b, out);
  else contract<P, W>(L, z, b, out);
}

// a * b + c * d + e * f as the AVX2 kernel's fmadd(e, f, fmadd(c, d, a * b)).
inline float32x4_t dot3(float32x4_t a, float32x4_t b, float32x4_t c, float32x4_t d, float32x4_t e, float32x4_t f) {
  return vfmaq_f32(vfmaq_f32(vmulq_f32(a, b), c, d), e, f);
}

// rhs += the right-hand side of the 8 faces of block b, given their G_f - I (d, row-major 3x3);
// one half (4 lanes) of the block at a time.
void accumulate_rhs(const Lanes* d, const FaceBlocks& faces, std::size_t b, const float* skin, float* rhs) {
  const std::int32_t* idx = faces.corners.data() + b * 3 * kLanes;
  const float* cf = faces.coeff.data() + b * 3 * kLanes;
  for (std::size_t half = 0; half < 2; ++half) {
    const std::size_t l0 = 4 * half;
    alignas(16) float edge[6][4];
    for (std::size_t l = 0; l < 4; ++l) {
      const float* si = skin + 3 * static_cast<std::size_t>(idx[l0 + l]);
      const float* sj = skin + 3 * static_cast<std::size_t>(idx[kLanes + l0 + l]);
      const float* sk = skin + 3 * static_cast<std::size_t>(idx[2 * kLanes + l0 + l]);
      for (int c = 0; c < 3; ++c) {
        edge[c][l] = sj[c] - si[c];
        edge[3 + c][l] = sk[c] - si[c];
      }
    }
    float32x4_t e[6];
    for (int c = 0; c < 6; ++c) e[c] = vld1q_f32(edge[c]);
    const float32x4_t c00 = vld1q_f32(cf + l0), c01 = vld1q_f32(cf + kLanes + l0), c11 = vld1q_f32(cf + 2 * kLanes + l0);
    float32x4x4_t corner[3];  // [i, j, k]: x, y, z and 0, a face per lane
    for (std::size_t r = 0; r < 3; ++r) {
      const float32x4_t m0 = half ? d[3 * r].hi : d[3 * r].lo, m1 = half ? d[3 * r + 1].hi : d[3 * r + 1].lo,
                        m2 = half ? d[3 * r + 2].hi : d[3 * r + 2].lo;
      const float32x4_t p0 = dot3(m0, e[0], m1, e[1], m2, e[2]), p1 = dot3(m0, e[3], m1, e[4], m2, e[5]);
      corner[1].val[r] = vfmaq_f32(vmulq_f32(p0, c00), p1, c01);
      corner[2].val[r] = vfmaq_f32(vmulq_f32(p0, c01), p1, c11);
      corner[0].val[r] = vnegq_f32(vaddq_f32(corner[1].val[r], corner[2].val[r]));
    }
    // As the AVX2 kernel: each face's (x, y, z, 0) added to its corner in one 16-byte add
    // (vst4q interleaves the four vectors into one per face).
    for (std::size_t k = 0; k < 3; ++k) {
      corner[k].val[3] = vdupq_n_f32(0.0f);
      alignas(16) float lanes[4][4];
      vst4q_f32(&lanes[0][0], corner[k]);
      for (std::size_t l = 0; l < 4; ++l) {
        float* a = rhs + kRhsStride * static_cast<std::size_t>(idx[k * kLanes + l0 + l]);
        vst1q_f32(a, vaddq_f32(vld1q_f32(a), vld1q_f32(lanes[l])));
      }
    }
  }
}

// out[v] = base[v] + add[v] + the 8 lanes of a (3 components), for the elements of block b that exist.
void write_offsets(const Lanes* a, const HyperTensor& L, std::size_t b, const float* base_pos, const float* add, float* out) {
  alignas(16) float acc[3][kLanes];
  for (int c = 0; c < 3; ++c) {
    vst1q_f32(acc[c], a[c].lo);
    vst1q_f32(acc[c] + 4, a[c].hi);
  }
  add_block_offsets(acc, L, b, base_pos, add, out);
}

template <Precision P>
void dg_rhs_blocks(const HyperTensor& L, const FaceBlocks& faces, const float* z, const float* skin, std::size_t b0,
                   std::size_t b1, float* rhs) {
  for (std::size_t b = b0; b < b1; ++b) {
    Lanes d[9];
    contract_any<P, 9>(L, z, b, d);
    accumulate_rhs(d, faces, b, skin, rhs);
  }
}

template <Precision P>
void vertex_offsets_blocks(const HyperTensor& L, const float* z, const float* base_pos, const float* add, std::size_t b0,
                           std::size_t b1, float* out) {
  for (std::size_t b = b0; b < b1; ++b) {
    Lanes a[3];
    contract_any<P, 3>(L, z, b, a);
    write_offsets(a, L, b, base_pos, add, out);
  }
}

}  // namespace

void dg_rhs(const HyperTensor& L, const FaceBlocks& faces, const float* z, const float* skin, std::size_t b0,
            std::size_t b1, float* rhs) {
  switch (L.precision()) {
    case Precision::Half: dg_rhs_blocks<Precision::Half>(L, faces, z, skin, b0, b1, rhs); return;
    case Precision::Float: dg_rhs_blocks<Precision::Float>(L, faces, z, skin, b0, b1, rhs); return;
    case Precision::Int8: dg_rhs_blocks<Precision::Int8>(L, faces, z, skin, b0, b1, rhs); return;
  }
}

void vertex_offsets(const HyperTensor& L, const float* z, const float* base, const float* add, std::size_t b0, std::size_t b1,
                    float* out) {
  switch (L.precision()) {
    case Precision::Half: vertex_offsets_blocks<Precision::Half>(L, z, base, add, b0, b1, out); return;
    case Precision::Float: vertex_offsets_blocks<Precision::Float>(L, z, base, add, b0, b1, out); return;
    case Precision::Int8: vertex_offsets_blocks<Precision::Int8>(L, z, base, add, b0, b1, out); return;
  }
}

}  // namespace softdeca::kernels::neon

#endif  // SOFTDECA_NEON
