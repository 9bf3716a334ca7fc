// Builds without libdraco (cross builds): primitives compressed with KHR_draco_mesh_compression
// are read from their uncompressed accessors where the file has them, refused by name otherwise.
#include "gltf_draco.h"
#include "gltf_json.h"

namespace softdeca::avatar_import::gltf {

bool draco_supported() { return false; }

DracoPrimitive decode_draco(std::string_view, std::uint32_t, std::uint64_t, std::uint64_t, const std::string& where) {
  throw Problem(where, "this build cannot decode KHR_draco_mesh_compression (it was built without Draco)");
}

}  // namespace softdeca::avatar_import::gltf
