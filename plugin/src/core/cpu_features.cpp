#include "core/cpu_features.h"

#include <cctype>
#include <cstdlib>
#include <string>

namespace softdeca {

namespace {

CpuFeatures detect() {
  CpuFeatures f;
#if defined(__x86_64__) || defined(__i386__)
  f.avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("f16c");
  f.avx512_vnni = f.avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                  __builtin_cpu_supports("avx512vnni");
#elif defined(__aarch64__) && defined(__ARM_NEON)
  f.neon = true;
#endif
  return f;
}

}  // namespace

CpuFeatures capped(CpuFeatures detected, CpuCap cap) {
  CpuFeatures f = detected;
  if (cap < CpuCap::Avx512) f.avx512_vnni = false;
  if (cap < CpuCap::Avx2) f.avx2 = false;
  if (cap < CpuCap::Neon) f.neon = false;
  return f;
}

bool parse_cpu_cap(const char* text, CpuCap& cap) {
  std::string s;
  for (const char* c = text; c != nullptr && *c != '\0'; ++c)
    s += static_cast<char>(std::tolower(static_cast<unsigned char>(*c)));
  if (s.empty() || s == "avx512") cap = CpuCap::Avx512;
  else if (s == "avx2") cap = CpuCap::Avx2;
  else if (s == "neon") cap = CpuCap::Neon;
  else if (s == "portable") cap = CpuCap::Portable;
  else return false;
  return true;
}

const CpuFeatures& cpu_features() {
  // Read once: the kernels of one process must not change family between frames.
  static const CpuFeatures features = [] {
    CpuCap cap = CpuCap::Avx512;
    if (!parse_cpu_cap(std::getenv("SOFTDECA_CPU"), cap)) cap = CpuCap::Portable;
    return capped(detect(), cap);
  }();
  return features;
}

const char* cpu_family_name() {
  const CpuFeatures& f = cpu_features();
  return f.avx512_vnni ? "avx512" : f.avx2 ? "avx2" : f.neon ? "neon" : "portable";
}

}  // namespace softdeca
