// Which vector instruction families the library's hand-written kernels may use: what the CPU
// reports, capped by the environment variable SOFTDECA_CPU, read once per process.
//
//   SOFTDECA_CPU=portable   only the portable loops (what any CPU without AVX2 or NEON runs)
//   SOFTDECA_CPU=neon       the NEON kernels (aarch64) and nothing of x86-64's
//   SOFTDECA_CPU=avx2       AVX2, FMA and F16C kernels, never AVX-512 (an x86-64 CPU without it)
//   SOFTDECA_CPU=avx512 / unset / empty   everything the CPU has
//
// The cap exists so that one machine can run the numerics on the kernel family another machine
// would choose (tests, docs/platforms.md); it never enables what the CPU lacks.
#pragma once

namespace softdeca {

struct CpuFeatures {
  bool avx2 = false;         // AVX2 + FMA + F16C
  bool avx512_vnni = false;  // AVX-512 F/VL + VNNI (implies avx2 here)
  bool neon = false;         // aarch64 Advanced SIMD: every aarch64 CPU has it
};

// The family names SOFTDECA_CPU accepts, lowest first (an architecture has NEON or AVX2, never
// both, so Neon below Avx2 only says that a cap of neon allows no x86-64 family).
enum class CpuCap { Portable, Neon, Avx2, Avx512 };

// `detected` limited to `cap`. Pure, for tests.
CpuFeatures capped(CpuFeatures detected, CpuCap cap);

// Parses a SOFTDECA_CPU value: false for anything but the names above (case-insensitive), "" is
// Avx512 (no cap).
bool parse_cpu_cap(const char* text, CpuCap& cap);

// The features this process's kernels use: detected once, capped by SOFTDECA_CPU. An
// unrecognised SOFTDECA_CPU value caps at Portable: a mistyped request for fewer instructions
// must not silently run more.
const CpuFeatures& cpu_features();

// "portable", "neon", "avx2" or "avx512": the family cpu_features() allows (benchmarks, `softdeca info`).
const char* cpu_family_name();

}  // namespace softdeca
