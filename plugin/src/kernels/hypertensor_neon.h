// The hyper-tensor products of hypertensor.h on aarch64's Advanced SIMD (NEON), which every
// aarch64 CPU has (Linux arm64, Android arm64-v8a, iOS and Apple silicon). The same arithmetic as
// the AVX2 kernels in the same order, each 8-lane block as two 4-lane registers: fused
// multiply-adds over the latents for half and float storage, exact int32 sums of int8 x int16
// products for int8 storage. hypertensor.cpp dispatches here as Kernel::Neon.
#pragma once

#include <cstddef>

#include "kernels/hypertensor.h"

#if defined(__aarch64__) && defined(__ARM_NEON)
#define SOFTDECA_NEON 1

namespace softdeca::kernels::neon {

// The most latents the int8 kernel takes (its int32 sums stay exact); more run the portable one.
constexpr int kMaxInt8Latent = 256;

void dg_rhs(const HyperTensor& L, const FaceBlocks& faces, const float* z, const float* skin, std::size_t b0,
            std::size_t b1, float* rhs);
void vertex_offsets(const HyperTensor& L, const float* z, const float* base, const float* add, std::size_t b0, std::size_t b1,
                    float* out);

}  // namespace softdeca::kernels::neon

#endif
