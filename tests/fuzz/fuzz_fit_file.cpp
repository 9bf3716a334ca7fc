// A saved fit: any bytes decode to a fit whose every index lies inside the sizes it was read
// for and whose every value lies in the ranges a fit holds, or are refused with softdeca::Error;
// never a read out of bounds or an unbounded allocation. The sizes are a small template's (6
// head, 4 skin vertices, 2 skin triangles, 1 identity mode). An input with a fit file's header
// gets its checksum put right first (a fuzzer would never find one), so that what is fuzzed is
// the reading behind it; the checksum's own refusal is tested in tests/native/test_fit_api.cpp.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "bundle/sha256.h"
#include "core/error.h"
#include "fit/fit_file.h"
#include "fuzz_check.h"

using namespace softdeca;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bundle(64, 'b');
  const fit::FitSizes sizes{6, 4, 2, 1};
  std::vector<uint8_t> bytes(data, data + size);
  if (bytes.size() >= fit::kFitHeaderBytes) {
    const std::string sum = bundle::sha256_hex(bytes.data() + fit::kFitHeaderBytes, bytes.size() - fit::kFitHeaderBytes);
    std::memcpy(bytes.data() + 12, sum.data(), sum.size());
  }
  try {
    const fit::AvatarFit f = fit::decode_fit(bytes.data(), bytes.size(), "fit", bundle, sizes);
    FUZZ_CHECK(f.registered.size() == 18);
    FUZZ_CHECK(f.source.corners.size() == 12 && f.source.weight.size() == 4);
    FUZZ_CHECK(f.identity.size() == 1);
    for (const int32_t c : f.source.corners) FUZZ_CHECK(c >= 0 && static_cast<std::size_t>(c) < f.vertex_count);
    for (std::size_t i = 0; i < f.embedding.size(); ++i) {
      FUZZ_CHECK(f.embedding.vertex[i] >= 0 && static_cast<std::size_t>(f.embedding.vertex[i]) < f.vertex_count);
      FUZZ_CHECK(f.embedding.triangle[i] >= 0 && f.embedding.triangle[i] < 2);
    }
    FUZZ_CHECK(fit::fit_out_of_range(f, sizes).empty());
    // what decodes encodes to the same bytes
    FUZZ_CHECK(fit::encode_fit(f, bundle, 4) == bytes);
  } catch (const Error&) {
  }
  return 0;
}
