// SOFTDECA_CPU: the cap on the kernel families, so one machine runs another CPU's numerics.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "core/cpu_features.h"

using softdeca::capped;
using softdeca::CpuCap;
using softdeca::CpuFeatures;
using softdeca::parse_cpu_cap;

TEST(CpuFeatures, ParsesTheFamilyNamesInAnyCase) {
  CpuCap cap = CpuCap::Portable;
  ASSERT_TRUE(parse_cpu_cap("AVX2", cap));
  EXPECT_EQ(cap, CpuCap::Avx2);
  ASSERT_TRUE(parse_cpu_cap("portable", cap));
  EXPECT_EQ(cap, CpuCap::Portable);
  ASSERT_TRUE(parse_cpu_cap("avx512", cap));
  EXPECT_EQ(cap, CpuCap::Avx512);
  cap = CpuCap::Portable;
  ASSERT_TRUE(parse_cpu_cap("", cap));
  EXPECT_EQ(cap, CpuCap::Avx512);
  ASSERT_TRUE(parse_cpu_cap(nullptr, cap));
  ASSERT_TRUE(parse_cpu_cap("NEON", cap));
  EXPECT_EQ(cap, CpuCap::Neon);
  EXPECT_FALSE(parse_cpu_cap("sse4", cap));
  EXPECT_FALSE(parse_cpu_cap("avx2 ", cap));
}

TEST(CpuFeatures, ACapRemovesFamiliesAndNeverAddsOne) {
  const CpuFeatures all{true, true, true};
  EXPECT_TRUE(capped(all, CpuCap::Avx512).avx512_vnni);
  EXPECT_TRUE(capped(all, CpuCap::Avx2).avx2);
  EXPECT_FALSE(capped(all, CpuCap::Avx2).avx512_vnni);
  EXPECT_FALSE(capped(all, CpuCap::Portable).avx2);
  EXPECT_FALSE(capped(all, CpuCap::Portable).neon);
  EXPECT_TRUE(capped(all, CpuCap::Neon).neon);
  const CpuFeatures none{};
  EXPECT_FALSE(capped(none, CpuCap::Avx512).avx2);
  EXPECT_FALSE(capped(none, CpuCap::Avx512).avx512_vnni);
}

TEST(CpuFeatures, TheProcessFamilyHonoursTheEnvironment) {
  // make test-kernels runs this suite under SOFTDECA_CPU=avx2 and portable too.
  const char* env = std::getenv("SOFTDECA_CPU");
  const std::string family = softdeca::cpu_family_name();
  const std::string asked = env != nullptr ? env : "";
  if (asked == "portable") {
    EXPECT_EQ(family, "portable");
  } else if (asked == "avx2") {
    EXPECT_NE(family, "avx512");
  }
#if defined(__aarch64__)
  EXPECT_TRUE(family == "portable" || family == "neon") << family;
#else
  EXPECT_TRUE(family == "portable" || family == "avx2" || family == "avx512") << family;
#endif
}
