// A saved fit: any bytes decode to a fit whose every index lies inside the sizes it was read
// for, or are refused with softdeca::Error; never a read out of bounds or an unbounded
// allocation. The sizes are a small template's (6 head, 4 skin vertices, 2 skin triangles).
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "fit/fit_file.h"
#include "fuzz_check.h"

using namespace softdeca;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bundle(64, 'b');
  try {
    const fit::AvatarFit f = fit::decode_fit(data, size, "fit", bundle, 6, 4, 2);
    FUZZ_CHECK(f.registered.size() == 18);
    FUZZ_CHECK(f.source.corners.size() == 12 && f.source.weight.size() == 4);
    for (const int32_t c : f.source.corners) FUZZ_CHECK(c >= 0 && static_cast<std::size_t>(c) < f.vertex_count);
    for (std::size_t i = 0; i < f.embedding.size(); ++i) {
      FUZZ_CHECK(f.embedding.vertex[i] >= 0 && static_cast<std::size_t>(f.embedding.vertex[i]) < f.vertex_count);
      FUZZ_CHECK(f.embedding.triangle[i] >= 0 && f.embedding.triangle[i] < 2);
    }
    // what decodes encodes to the same bytes
    FUZZ_CHECK(fit::encode_fit(f, bundle, 4) == std::vector<uint8_t>(data, data + size));
  } catch (const Error&) {
  }
  return 0;
}
