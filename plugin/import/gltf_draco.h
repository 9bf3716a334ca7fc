// KHR_draco_mesh_compression: a primitive's positions and triangles stored as one Draco mesh.
// Decoded with the system's libdraco where the build found it; a build without it reads the
// primitive's uncompressed accessors where the file has them and refuses it by name otherwise.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace softdeca::avatar_import::gltf {

struct DracoPrimitive {
  std::vector<float> positions;        // point count x 3, in Draco's point order
  std::vector<std::uint32_t> indices;  // face count x 3
};

bool draco_supported();

// The mesh in `bytes` (the extension's buffer view): the attribute whose unique id is
// `position_id` as 3 floats a point, and its faces. `max_points` and `max_faces` bound what is
// copied out. Throws Problem at `where` when the data does not decode or does not fit.
DracoPrimitive decode_draco(std::string_view bytes, std::uint32_t position_id, std::uint64_t max_points, std::uint64_t max_faces,
                            const std::string& where);

}  // namespace softdeca::avatar_import::gltf
