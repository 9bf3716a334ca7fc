#include "kernels/hypertensor.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/cpu_features.h"
#include "kernels/half.h"
#include "kernels/hypertensor_neon.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SOFTDECA_X86 1
#endif

namespace softdeca::kernels {

HyperTensor::HyperTensor(const float* source, std::size_t n, int latent, int width, Precision precision,
                         const std::int32_t* order)
    : n_(n), latent_(latent), width_(width), precision_(precision) {
  const std::size_t total = blocks() * block_stride();
  const std::size_t count = n * static_cast<std::size_t>(latent) * static_cast<std::size_t>(width);
  zero_ = std::all_of(source, source + count, [](float v) { return v == 0.0f; });
  peaks_.assign(static_cast<std::size_t>(latent), 0.0f);
  const auto source_at = [&](std::size_t e, int k, int c) {
    const std::size_t row = order ? static_cast<std::size_t>(order[e]) : e;
    return source[(row * static_cast<std::size_t>(latent) + static_cast<std::size_t>(k)) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(c)];
  };
  if (precision == Precision::Int8) {
    // One scale per block and latent: the largest magnitude of its width x 8 values maps to 127.
    int8_.resize(total);  // zero: the padding latent and lanes past the last element
    scales_.resize(blocks() * static_cast<std::size_t>(latent));
    for (std::size_t b = 0; b < blocks(); ++b)
      for (int k = 0; k < latent; ++k) {
        float peak = 0;
        for (std::size_t e = b * kLanes; e < std::min(n, (b + 1) * kLanes); ++e)
          for (int c = 0; c < width; ++c) peak = std::max(peak, std::fabs(source_at(e, k, c)));
        const float scale = peak > 0 ? peak / 127.0f : 1.0f;
        if (peak > 0) peaks_[static_cast<std::size_t>(k)] = std::max(peaks_[static_cast<std::size_t>(k)], 127.0f * scale);
        scales_[b * static_cast<std::size_t>(latent) + static_cast<std::size_t>(k)] = scale;
        for (std::size_t e = b * kLanes; e < std::min(n, (b + 1) * kLanes); ++e)
          for (int c = 0; c < width; ++c)
            int8_[index(b, k, c, e % kLanes)] = static_cast<std::int8_t>(std::lround(source_at(e, k, c) / scale));
      }
    return;
  }
  if (precision == Precision::Half) half_.resize(total);
  else float_.resize(total);
  for (std::size_t e = 0; e < n; ++e) {
    const std::size_t b = e / kLanes, lane = e % kLanes;
    for (int k = 0; k < latent; ++k)
      for (int c = 0; c < width; ++c) {
        const float v = source_at(e, k, c);
        const std::size_t at = index(b, k, c, lane);
        if (precision == Precision::Half) half_[at] = float_to_half(v);
        else float_[at] = v;
        const float stored = precision == Precision::Half ? half_to_float(half_[at]) : v;
        float& peak = peaks_[static_cast<std::size_t>(k)];
        peak = std::max(peak, std::fabs(stored));
      }
  }
}

float HyperTensor::at(std::size_t e, int k, int c) const {
  const std::size_t i = index(e / kLanes, k, c, e % kLanes);
  switch (precision_) {
    case Precision::Half: return half_to_float(half_[i]);
    case Precision::Float: return float_[i];
    case Precision::Int8: return int8_[i] * scales_[(e / kLanes) * static_cast<std::size_t>(latent_) + static_cast<std::size_t>(k)];
  }
  return 0;
}

namespace {

// The SIMD int8 kernels sum int16 x int8 products in int32: |sum| <= K * 32767 * 127 < 2^31 up
// to this many latents (more run the portable kernel).
constexpr int kMaxInt8Latent = 256;
#ifdef SOFTDECA_NEON
static_assert(neon::kMaxInt8Latent >= kMaxInt8Latent, "resolve() sends the NEON kernel up to kMaxInt8Latent latents");
#endif

// ---- portable kernels -----------------------------------------------------------------------

// d[c][lane] = sum_k z_k L[b, k, c] (c < W), the storage's branch taken once per block and the
// inner loops over the 8 lanes left to the compiler's vectoriser (NEON, SSE2).
template <int W>
void contract_portable(const HyperTensor& L, const float* z, std::size_t b, float (*d)[kLanes]) {
  for (int c = 0; c < W; ++c)
    for (std::size_t l = 0; l < kLanes; ++l) d[c][l] = 0.0f;
  const int K = L.latent();
  const std::size_t base = b * L.block_stride();
  switch (L.precision()) {
    case Precision::Float:
    case Precision::Half: {
      const bool half = L.precision() == Precision::Half;
      for (int k = 0; k < K; ++k) {
        const float zk = z[k];
        const std::size_t at = base + static_cast<std::size_t>(k) * W * kLanes;
        for (int c = 0; c < W; ++c) {
          const std::size_t row = at + static_cast<std::size_t>(c) * kLanes;
          if (half)
            for (std::size_t l = 0; l < kLanes; ++l) d[c][l] += zk * half_to_float(L.half_data()[row + l]);
          else
            for (std::size_t l = 0; l < kLanes; ++l) d[c][l] += zk * L.float_data()[row + l];
        }
      }
      break;
    }
    case Precision::Int8: {
      const float* s = L.scales() + b * static_cast<std::size_t>(K);
      for (int k = 0; k < K; ++k) {
        const float zk = z[k] * s[k];
        const std::int8_t* q = L.int8_data() + base + static_cast<std::size_t>(k / 2) * W * 2 * kLanes + static_cast<std::size_t>(k % 2);
        for (int c = 0; c < W; ++c)
          for (std::size_t l = 0; l < kLanes; ++l) d[c][l] += zk * static_cast<float>(q[(static_cast<std::size_t>(c) * kLanes + l) * 2]);
      }
      break;
    }
  }
}

void dg_rhs_portable(const HyperTensor& L, const FaceBlocks& faces, const float* z, const float* skin, std::size_t b0,
                     std::size_t b1, float* rhs) {
  for (std::size_t b = b0; b < b1; ++b) {
    float d[9][kLanes];
    contract_portable<9>(L, z, b, d);
    const std::int32_t* idx = faces.corners.data() + b * 3 * kLanes;
    const float* cf = faces.coeff.data() + b * 3 * kLanes;
    for (std::size_t l = 0; l < kLanes; ++l) {
      const std::size_t i = static_cast<std::size_t>(idx[l]), j = static_cast<std::size_t>(idx[kLanes + l]),
                        kk = static_cast<std::size_t>(idx[2 * kLanes + l]);
      float e1[3], e2[3];
      for (std::size_t c = 0; c < 3; ++c) {
        e1[c] = skin[3 * j + c] - skin[3 * i + c];
        e2[c] = skin[3 * kk + c] - skin[3 * i + c];
      }
      const float c00 = cf[l], c01 = cf[kLanes + l], c11 = cf[2 * kLanes + l];
      for (std::size_t r = 0; r < 3; ++r) {
        const float p0 = d[3 * r][l] * e1[0] + d[3 * r + 1][l] * e1[1] + d[3 * r + 2][l] * e1[2];
        const float p1 = d[3 * r][l] * e2[0] + d[3 * r + 1][l] * e2[1] + d[3 * r + 2][l] * e2[2];
        const float col0 = p0 * c00 + p1 * c01, col1 = p0 * c01 + p1 * c11;
        rhs[kRhsStride * j + r] += col0;
        rhs[kRhsStride * kk + r] += col1;
        rhs[kRhsStride * i + r] -= col0 + col1;
      }
    }
  }
}

void vertex_offsets_portable(const HyperTensor& L, const float* z, const float* base_pos, const float* add, std::size_t b0,
                             std::size_t b1, float* out) {
  for (std::size_t b = b0; b < b1; ++b) {
    float acc[3][kLanes];
    contract_portable<3>(L, z, b, acc);
    add_block_offsets(acc, L, b, base_pos, add, out);
  }
}

#ifdef SOFTDECA_X86
// ---- AVX2 + FMA + F16C kernels ----------------------------------------------------------------

template <Precision P>
__attribute__((target("avx2,fma,f16c"))) inline __m256 load8(const HyperTensor& L, std::size_t at) {
  if constexpr (P == Precision::Half)
    return _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(L.half_data() + at)));
  else
    return _mm256_loadu_ps(L.float_data() + at);
}

// out[c] (8 lanes) = sum_k z_k L[b, k, c] for c < W, half or float storage. Each sum is a
// chain of fused multiply-adds, each waiting on the one before (4 cycles); a width-3 table
// (vertex offsets) would keep only three chains in flight, a third of what two FMA units take,
// so its latents are dealt round-robin to S sets of accumulators (S W >= 8 chains), added up
// at the end.
template <Precision P, int W>
__attribute__((target("avx2,fma,f16c"))) inline void contract(const HyperTensor& L, const float* z, std::size_t b, __m256* out) {
  constexpr int S = W >= 8 ? 1 : (8 + W - 1) / W;
  const int K = L.latent();
  const std::size_t base = b * L.block_stride();
  __m256 acc[S][W];
  for (int s = 0; s < S; ++s)
    for (int c = 0; c < W; ++c) acc[s][c] = _mm256_setzero_ps();
  int k = 0;
  for (; k + S <= K; k += S) {
#pragma GCC unroll 3
    for (int s = 0; s < S; ++s) {
      const __m256 zk = _mm256_set1_ps(z[k + s]);
      const std::size_t at = base + static_cast<std::size_t>(k + s) * W * kLanes;
#pragma GCC unroll 9
      for (int c = 0; c < W; ++c)
        acc[s][c] = _mm256_fmadd_ps(zk, load8<P>(L, at + static_cast<std::size_t>(c) * kLanes), acc[s][c]);
    }
  }
  for (; k < K; ++k) {
    const __m256 zk = _mm256_set1_ps(z[k]);
    const std::size_t at = base + static_cast<std::size_t>(k) * W * kLanes;
#pragma GCC unroll 9
    for (int c = 0; c < W; ++c) acc[0][c] = _mm256_fmadd_ps(zk, load8<P>(L, at + static_cast<std::size_t>(c) * kLanes), acc[0][c]);
  }
  for (int c = 0; c < W; ++c) {
    out[c] = acc[0][c];
    for (int s = 1; s < S; ++s) out[c] = _mm256_add_ps(out[c], acc[s][c]);
  }
}

// The same for int8 storage: the block's coefficients z_k s_{b,k} are quantised to int16 in two
// parts, a coarse one with the step t = max_k |z_k s_{b,k}| / 32767 and the remainder with the
// step t / 32768, multiplied with the int8 values two latents at a time by pmaddwd, each summed
// exactly in int32 (kMaxInt8Latent), then scaled by their steps. One part alone would round every
// term to a step set by the block's largest one: where a large term cancels against others (a
// vertex stage's collinear columns) that error reached 0.09 mm on a trained bundle, 25 times
// the int8 storage's own. With both parts it is 2^-15 of that, below float rounding.

// z_k s_{b,k} of block b as the int16 pair (zq, zr): z_k s_{b,k} = t (zq_k + zr_k / 32768) up to
// float rounding, padded with zeros to an even count; returns t (0 when every coefficient is 0).
__attribute__((target("avx2,fma"))) inline float quantise_coefficients(const HyperTensor& L, const float* z, std::size_t b,
                                                                     std::int16_t* zq, std::int16_t* zr) {
  const int K = L.latent(), K16 = (K + 15) / 16 * 16;
  const float* s = L.scales() + b * static_cast<std::size_t>(K);
  alignas(32) float zs[kMaxInt8Latent];
  for (int k = 0; k < K; ++k) zs[k] = z[k] * s[k];
  for (int k = K; k < K16; ++k) zs[k] = 0.0f;
  const __m256 sign = _mm256_set1_ps(-0.0f);
  __m256 peak8 = _mm256_setzero_ps();
  for (int k = 0; k < K16; k += 8) peak8 = _mm256_max_ps(peak8, _mm256_andnot_ps(sign, _mm256_load_ps(zs + k)));
  __m128 peak4 = _mm_max_ps(_mm256_castps256_ps128(peak8), _mm256_extractf128_ps(peak8, 1));
  peak4 = _mm_max_ps(peak4, _mm_movehl_ps(peak4, peak4));
  peak4 = _mm_max_ss(peak4, _mm_shuffle_ps(peak4, peak4, 1));
  const float peak = _mm_cvtss_f32(peak4);
  if (!(peak > 0.0f)) return 0.0f;
  const __m256 inv = _mm256_set1_ps(32767.0f / peak), fine = _mm256_set1_ps(32768.0f);
  for (int k = 0; k < K16; k += 16) {
    const __m256 x0 = _mm256_mul_ps(_mm256_load_ps(zs + k), inv), x1 = _mm256_mul_ps(_mm256_load_ps(zs + k + 8), inv);
    const __m256i a = _mm256_cvtps_epi32(x0), c = _mm256_cvtps_epi32(x1);
    // |x - round(x)| <= 1/2, so the remainder times 32768 fits int16
    const __m256i ra = _mm256_cvtps_epi32(_mm256_mul_ps(_mm256_sub_ps(x0, _mm256_cvtepi32_ps(a)), fine));
    const __m256i rc = _mm256_cvtps_epi32(_mm256_mul_ps(_mm256_sub_ps(x1, _mm256_cvtepi32_ps(c)), fine));
    // packs works per 128-bit half: (a0-3, c0-3 | a4-7, c4-7); restore the order.
    _mm256_store_si256(reinterpret_cast<__m256i*>(zq + k), _mm256_permute4x64_epi64(_mm256_packs_epi32(a, c), 0xD8));
    _mm256_store_si256(reinterpret_cast<__m256i*>(zr + k), _mm256_permute4x64_epi64(_mm256_packs_epi32(ra, rc), 0xD8));
  }
  return peak / 32767.0f;
}

// Two latents of 8 int8 values (widened to int16) times the int16 pair (z_k, z_k+1), summed in
// int32 and added to acc: pmaddwd + paddd on AVX2, one vpdpwssd with AVX-512 VNNI.
struct PairsAvx2 {
  __attribute__((target("avx2"))) static inline __m256i mac(__m256i acc, __m256i v, __m256i zp) {
    return _mm256_add_epi32(acc, _mm256_madd_epi16(v, zp));
  }
};
struct PairsVnni {
  __attribute__((target("avx2,avx512f,avx512vl,avx512vnni"))) static inline __m256i mac(__m256i acc, __m256i v, __m256i zp) {
    return _mm256_dpwssd_epi32(acc, v, zp);
  }
};

// The kernels below are templates on the storage (P) and the int8 pair instruction (Pairs).
// They carry the AVX2 target and are always inlined: a VNNI entry point (which has the AVX-512
// target) inlines them with PairsVnni, whose instruction then inlines too. A template cannot
// take its target from a template argument, hence this arrangement.
#define SOFTDECA_KERNEL __attribute__((target("avx2,fma,f16c"), always_inline)) inline

template <int W, class Pairs>
SOFTDECA_KERNEL void contract_int8(const HyperTensor& L, const float* z, std::size_t b, __m256* out) {
  alignas(32) std::int16_t zq[kMaxInt8Latent], zr[kMaxInt8Latent];
  const float t = quantise_coefficients(L, z, b, zq, zr);
  for (int c = 0; c < W; ++c) out[c] = _mm256_setzero_ps();
  if (t == 0.0f) return;
  __m256i coarse[W], rest[W];
  for (int c = 0; c < W; ++c) coarse[c] = rest[c] = _mm256_setzero_si256();
  const std::int8_t* q = L.int8_data() + b * L.block_stride();
  const int pairs = (L.latent() + 1) / 2;
  for (int p = 0; p < pairs; ++p) {
    std::int32_t pair, pair_rest;
    std::memcpy(&pair, zq + 2 * p, sizeof pair);
    std::memcpy(&pair_rest, zr + 2 * p, sizeof pair_rest);
    const __m256i zp = _mm256_set1_epi32(pair), zp_rest = _mm256_set1_epi32(pair_rest);
    const std::int8_t* qp = q + static_cast<std::size_t>(p) * W * 2 * kLanes;
#pragma GCC unroll 9
    for (int c = 0; c < W; ++c) {
      const __m256i v = _mm256_cvtepi8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(qp + c * 2 * kLanes)));
      coarse[c] = Pairs::mac(coarse[c], v, zp);
      rest[c] = Pairs::mac(rest[c], v, zp_rest);
    }
  }
  const __m256 step = _mm256_set1_ps(t), fine = _mm256_set1_ps(t / 32768.0f);
  for (int c = 0; c < W; ++c)
    out[c] = _mm256_fmadd_ps(_mm256_cvtepi32_ps(rest[c]), fine, _mm256_mul_ps(_mm256_cvtepi32_ps(coarse[c]), step));
}

template <Precision P, int W, class Pairs>
SOFTDECA_KERNEL void contract_any(const HyperTensor& L, const float* z, std::size_t b, __m256* out) {
  if constexpr (P == Precision::Int8) contract_int8<W, Pairs>(L, z, b, out);
  else contract<P, W>(L, z, b, out);
}

// rhs += the right-hand side of the 8 faces of block b, given their G_f - I (d, row-major 3x3).
__attribute__((target("avx2,fma"))) inline void accumulate_rhs(const __m256* d, const FaceBlocks& faces, std::size_t b,
                                                              const float* skin, float* rhs) {
  const std::int32_t* idx = faces.corners.data() + b * 3 * kLanes;
  // Edge vectors of the 8 faces, transposed to one lane per face (scalar loads: AVX2 gathers
  // are slow on several CPUs and these vertices are in cache).
  alignas(32) float edge[6][kLanes];
  for (std::size_t l = 0; l < kLanes; ++l) {
    const float* si = skin + 3 * static_cast<std::size_t>(idx[l]);
    const float* sj = skin + 3 * static_cast<std::size_t>(idx[kLanes + l]);
    const float* sk = skin + 3 * static_cast<std::size_t>(idx[2 * kLanes + l]);
    for (int c = 0; c < 3; ++c) {
      edge[c][l] = sj[c] - si[c];
      edge[3 + c][l] = sk[c] - si[c];
    }
  }
  const __m256 e1[3] = {_mm256_load_ps(edge[0]), _mm256_load_ps(edge[1]), _mm256_load_ps(edge[2])};
  const __m256 e2[3] = {_mm256_load_ps(edge[3]), _mm256_load_ps(edge[4]), _mm256_load_ps(edge[5])};
  const float* cf = faces.coeff.data() + b * 3 * kLanes;
  const __m256 c00 = _mm256_loadu_ps(cf), c01 = _mm256_loadu_ps(cf + kLanes), c11 = _mm256_loadu_ps(cf + 2 * kLanes);
  __m256 c[3][3];  // [corner i, j, k][x, y, z], a face per lane
  for (int r = 0; r < 3; ++r) {
    const __m256* row = d + 3 * r;
    const __m256 p0 = _mm256_fmadd_ps(row[2], e1[2], _mm256_fmadd_ps(row[1], e1[1], _mm256_mul_ps(row[0], e1[0])));
    const __m256 p1 = _mm256_fmadd_ps(row[2], e2[2], _mm256_fmadd_ps(row[1], e2[1], _mm256_mul_ps(row[0], e2[0])));
    c[1][r] = _mm256_fmadd_ps(p1, c01, _mm256_mul_ps(p0, c00));
    c[2][r] = _mm256_fmadd_ps(p1, c11, _mm256_mul_ps(p0, c01));
    c[0][r] = _mm256_sub_ps(_mm256_setzero_ps(), _mm256_add_ps(c[1][r], c[2][r]));
  }
  // Each corner's (x, y, z) vectors to one (x, y, z, 0) per face (a 4 x 8 transpose), each added
  // to its vertex in one 16-byte add. Faces of one block share vertices, so these adds wait on
  // each other through memory: one chain per corner where there were three.
  const __m256 zero = _mm256_setzero_ps();
  for (int k = 0; k < 3; ++k) {
    const __m256 xy_lo = _mm256_unpacklo_ps(c[k][0], c[k][1]), xy_hi = _mm256_unpackhi_ps(c[k][0], c[k][1]);
    const __m256 z_lo = _mm256_unpacklo_ps(c[k][2], zero), z_hi = _mm256_unpackhi_ps(c[k][2], zero);
    const __m256 l04 = _mm256_shuffle_ps(xy_lo, z_lo, 0x44), l15 = _mm256_shuffle_ps(xy_lo, z_lo, 0xEE);
    const __m256 l26 = _mm256_shuffle_ps(xy_hi, z_hi, 0x44), l37 = _mm256_shuffle_ps(xy_hi, z_hi, 0xEE);
    const __m256 pairs[4] = {_mm256_permute2f128_ps(l04, l15, 0x20), _mm256_permute2f128_ps(l26, l37, 0x20),
                             _mm256_permute2f128_ps(l04, l15, 0x31), _mm256_permute2f128_ps(l26, l37, 0x31)};
    const std::int32_t* corner = idx + k * static_cast<int>(kLanes);
    for (std::size_t l = 0; l < kLanes; l += 2) {
      const __m256 p = pairs[l / 2];  // lanes l and l + 1
      float* a = rhs + kRhsStride * static_cast<std::size_t>(corner[l]);
      float* b = rhs + kRhsStride * static_cast<std::size_t>(corner[l + 1]);
      _mm_storeu_ps(a, _mm_add_ps(_mm_loadu_ps(a), _mm256_castps256_ps128(p)));
      _mm_storeu_ps(b, _mm_add_ps(_mm_loadu_ps(b), _mm256_extractf128_ps(p, 1)));
    }
  }
}

// out[v] = base[v] + add[v] + the 8 lanes of a (3 components), for the elements of block b that exist.
__attribute__((target("avx2"))) inline void write_offsets(const __m256* a, const HyperTensor& L, std::size_t b, const float* base_pos,
                                                        const float* add, float* out) {
  alignas(32) float acc[3][kLanes];
  for (int c = 0; c < 3; ++c) _mm256_store_ps(acc[c], a[c]);
  add_block_offsets(acc, L, b, base_pos, add, out);
}

template <Precision P, class Pairs>
SOFTDECA_KERNEL void dg_rhs_blocks(const HyperTensor& L, const FaceBlocks& faces, const float* z, const float* skin,
                                   std::size_t b0, std::size_t b1, float* rhs) {
  for (std::size_t b = b0; b < b1; ++b) {
    __m256 d[9];
    contract_any<P, 9, Pairs>(L, z, b, d);
    accumulate_rhs(d, faces, b, skin, rhs);
  }
}

template <Precision P, class Pairs>
SOFTDECA_KERNEL void vertex_offsets_blocks(const HyperTensor& L, const float* z, const float* base_pos, const float* add,
                                           std::size_t b0, std::size_t b1, float* out) {
  for (std::size_t b = b0; b < b1; ++b) {
    __m256 a[3];
    contract_any<P, 3, Pairs>(L, z, b, a);
    write_offsets(a, L, b, base_pos, add, out);
  }
}
#undef SOFTDECA_KERNEL

// The entry points: one per storage on AVX2, int8 only with VNNI.
template <Precision P>
__attribute__((target("avx2,fma,f16c"))) void dg_rhs_avx2(const HyperTensor& L, const FaceBlocks& faces, const float* z,
                                                         const float* skin, std::size_t b0, std::size_t b1, float* rhs) {
  dg_rhs_blocks<P, PairsAvx2>(L, faces, z, skin, b0, b1, rhs);
}

__attribute__((target("avx2,fma,f16c,avx512f,avx512vl,avx512vnni"), flatten)) void dg_rhs_vnni(
    const HyperTensor& L, const FaceBlocks& faces, const float* z, const float* skin, std::size_t b0, std::size_t b1, float* rhs) {
  dg_rhs_blocks<Precision::Int8, PairsVnni>(L, faces, z, skin, b0, b1, rhs);
}

template <Precision P>
__attribute__((target("avx2,fma,f16c"))) void vertex_offsets_avx2(const HyperTensor& L, const float* z, const float* base_pos,
                                                                 const float* add, std::size_t b0, std::size_t b1, float* out) {
  vertex_offsets_blocks<P, PairsAvx2>(L, z, base_pos, add, b0, b1, out);
}

__attribute__((target("avx2,fma,f16c,avx512f,avx512vl,avx512vnni"), flatten)) void vertex_offsets_vnni(
    const HyperTensor& L, const float* z, const float* base_pos, const float* add, std::size_t b0, std::size_t b1, float* out) {
  vertex_offsets_blocks<Precision::Int8, PairsVnni>(L, z, base_pos, add, b0, b1, out);
}

bool cpu_has_avx2() { return cpu_features().avx2; }
bool cpu_has_vnni() { return cpu_features().avx512_vnni; }
#endif

// The kernel that runs: the one asked for, or (Best) the fastest this CPU has for L.
Kernel resolve(Kernel k, const HyperTensor& L) {
  const bool int8_ok = L.precision() != Precision::Int8 || L.latent() <= kMaxInt8Latent;
  if (k == Kernel::Best) {
    if (kernel_available(Kernel::Avx512Vnni) && L.precision() == Precision::Int8 && int8_ok) return Kernel::Avx512Vnni;
    if (kernel_available(Kernel::Avx2) && int8_ok) return Kernel::Avx2;
    if (kernel_available(Kernel::Neon) && int8_ok) return Kernel::Neon;
    return Kernel::Portable;
  }
  if (!kernel_available(k) || !int8_ok || (k == Kernel::Avx512Vnni && L.precision() != Precision::Int8)) return Kernel::Portable;
  return k;
}

}  // namespace

bool kernel_available(Kernel k) {
  switch (k) {
    case Kernel::Best:
    case Kernel::Portable: return true;
#ifdef SOFTDECA_X86
    case Kernel::Avx2: return cpu_has_avx2();
    case Kernel::Avx512Vnni: return cpu_has_vnni();
#else
    case Kernel::Avx2:
    case Kernel::Avx512Vnni: return false;
#endif
#ifdef SOFTDECA_NEON
    case Kernel::Neon: return cpu_features().neon;
#else
    case Kernel::Neon: return false;
#endif
  }
  return false;
}

void dg_rhs(const HyperTensor& L, const FaceBlocks& faces, const float* z, const float* skin, std::size_t b0, std::size_t b1,
            float* rhs, Kernel kernel) {
  switch (resolve(kernel, L)) {
#ifdef SOFTDECA_X86
    case Kernel::Avx512Vnni: dg_rhs_vnni(L, faces, z, skin, b0, b1, rhs); return;
    case Kernel::Avx2:
      switch (L.precision()) {
        case Precision::Half: dg_rhs_avx2<Precision::Half>(L, faces, z, skin, b0, b1, rhs); return;
        case Precision::Float: dg_rhs_avx2<Precision::Float>(L, faces, z, skin, b0, b1, rhs); return;
        case Precision::Int8: dg_rhs_avx2<Precision::Int8>(L, faces, z, skin, b0, b1, rhs); return;
      }
      return;
#endif
#ifdef SOFTDECA_NEON
    case Kernel::Neon: neon::dg_rhs(L, faces, z, skin, b0, b1, rhs); return;
#endif
    default: dg_rhs_portable(L, faces, z, skin, b0, b1, rhs); return;
  }
}

void vertex_offsets(const HyperTensor& L, const float* z, const float* base, const float* add, std::size_t b0,
                    std::size_t b1, float* out, Kernel kernel) {
  switch (resolve(kernel, L)) {
#ifdef SOFTDECA_X86
    case Kernel::Avx512Vnni: vertex_offsets_vnni(L, z, base, add, b0, b1, out); return;
    case Kernel::Avx2:
      switch (L.precision()) {
        case Precision::Half: vertex_offsets_avx2<Precision::Half>(L, z, base, add, b0, b1, out); return;
        case Precision::Float: vertex_offsets_avx2<Precision::Float>(L, z, base, add, b0, b1, out); return;
        case Precision::Int8: vertex_offsets_avx2<Precision::Int8>(L, z, base, add, b0, b1, out); return;
      }
      return;
#endif
#ifdef SOFTDECA_NEON
    case Kernel::Neon: neon::vertex_offsets(L, z, base, add, b0, b1, out); return;
#endif
    default: vertex_offsets_portable(L, z, base, add, b0, b1, out); return;
  }
}

}  // namespace softdeca::kernels
