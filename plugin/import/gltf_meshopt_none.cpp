// Builds without libmeshoptimizer (cross builds): views compressed with EXT_meshopt_compression
// are read from their uncompressed fallback where the file has one, refused by name otherwise.
#include "gltf_meshopt.h"

namespace softdeca::avatar_import::gltf {

bool meshopt_supported() { return false; }

void decode_meshopt(const MeshoptView&, std::string_view, unsigned char*, const std::string& where) {
  throw Problem(where, "this build cannot decode EXT_meshopt_compression (it was built without meshoptimizer)");
}

}  // namespace softdeca::avatar_import::gltf
