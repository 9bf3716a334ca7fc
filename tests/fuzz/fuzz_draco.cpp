// A KHR_draco_mesh_compression stream (import/gltf_draco_header.cpp, then gltf_draco.cpp): the
// counts read ahead of libdraco parse or refuse with std::runtime_error, and a stream they pass
// decodes within them or is refused, never reading past its bytes. The seeds are libdraco's own
// streams, both methods, with and without metadata.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "gltf_draco.h"
#include "gltf_draco_header.h"

using namespace softdeca::avatar_import::gltf;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  DracoCounts counts;
  try {
    counts = read_draco_counts(bytes, "fuzz");
  } catch (const std::runtime_error&) {
    return 0;
  }
  // What an accessor of the glTF would allow: small, so that a passing stream is decoded.
  constexpr std::uint64_t kPoints = 4096, kFaces = 8192;
  if (counts.vertices > kPoints || counts.faces > kFaces) return 0;
  try {
    const DracoPrimitive mesh = decode_draco(bytes, 0, kPoints, kFaces, "fuzz");
    FUZZ_CHECK(mesh.positions.size() % 3 == 0 && mesh.positions.size() / 3 <= kPoints);
    FUZZ_CHECK(mesh.indices.size() % 3 == 0 && mesh.indices.size() / 3 <= kFaces);
    for (const std::uint32_t i : mesh.indices) FUZZ_CHECK(i < mesh.positions.size() / 3);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
