// The OBJ reader (import/obj_reader.cpp) on any text: it parses or refuses with
// std::runtime_error; what parses has finite vertices, triangles that name them, and counts
// within the limits (small here, so that the limit checks are reached too).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_check.h"
#include "obj_reader.h"

using namespace softdeca::avatar_import;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ImportLimits limits;
  limits.max_vertices = 4096;
  limits.max_triangles = 8192;
  try {
    const ObjMesh mesh = parse_obj(std::string(reinterpret_cast<const char*>(data), size), "fuzz.obj", limits);
    FUZZ_CHECK(mesh.vertices.size() % 3 == 0 && mesh.vertex_count() <= limits.max_vertices);
    FUZZ_CHECK(mesh.triangles.size() % 3 == 0 && mesh.triangles.size() / 3 <= limits.max_triangles);
    for (const float v : mesh.vertices) FUZZ_CHECK(std::isfinite(v));
    for (const std::int32_t t : mesh.triangles) FUZZ_CHECK(t >= 0 && static_cast<std::size_t>(t) < mesh.vertex_count());
  } catch (const std::runtime_error&) {
  }
  return 0;
}
