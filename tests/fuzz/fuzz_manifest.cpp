// The bundle manifest and the JSON reader under it: any text parses into a checked manifest
// or is refused with softdeca::Error; never a crash, a read out of bounds or runaway recursion.
#include <cstddef>
#include <cstdint>
#include <string>

#include "api/error_boundary.h"
#include "bundle/json.h"
#include "bundle/manifest.h"
#include "fuzz_check.h"

using namespace softdeca::bundle;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    Json::parse(text);
  } catch (const softdeca::Error&) {
  }
  try {
    const Manifest m = parse_manifest(text);
    FUZZ_CHECK(m.has_softdeca || m.has_sparse);
    FUZZ_CHECK(m.skin_vertices <= m.head_vertices);
    for (const auto& [key, n] : m.networks) FUZZ_CHECK(n.sha256.size() == 64);
  } catch (const softdeca::Error&) {
  }
  return 0;
}
