// KHR_draco_mesh_compression through libdraco. The decoder checks the stream; what it hands
// back is checked again here (every point's value index and every face's corners within range)
// before anything is read from it.
#include <draco/compression/decode.h>

#include <cstring>

#include "gltf_draco.h"
#include "gltf_json.h"

namespace softdeca::avatar_import::gltf {

bool draco_supported() { return true; }

DracoPrimitive decode_draco(std::string_view bytes, std::uint32_t position_id, std::uint64_t max_points, std::uint64_t max_faces,
                            const std::string& where) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    throw Problem(where, std::string("its KHR_draco_mesh_compression data does not decode (") + decoded.status().error_msg() + ")");
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  const std::uint64_t points = mesh->num_points(), faces = mesh->num_faces();
  if (points > max_points)
    throw Problem(where, "its Draco mesh has " + std::to_string(points) + " points, more than its POSITION accessor's " +
                             std::to_string(max_points));
  if (faces > max_faces)
    throw Problem(where, "its Draco mesh has " + std::to_string(faces) + " faces, more than the " + std::to_string(max_faces) +
                             " triangles an avatar may have");
  const draco::PointAttribute* position = mesh->GetAttributeByUniqueId(position_id);
  if (!position) throw Problem(where, "its Draco mesh has no attribute " + std::to_string(position_id) + " (its POSITION)");
  if (position->num_components() != 3)
    throw Problem(where, "its Draco POSITION has " + std::to_string(position->num_components()) + " components, not 3");
  // Read as the 32-bit floats glTF's POSITION is, byte for byte: libdraco's ConvertValue would
  // also read the stream's "normalized" byte as a bool, whatever value the stream gave it.
  if (position->data_type() != draco::DT_FLOAT32 || position->byte_stride() < 12)
    throw Problem(where, "its Draco POSITION is not stored as 3 32-bit floats a point");
  DracoPrimitive out;
  out.positions.resize(3 * static_cast<std::size_t>(points));
  for (draco::PointIndex p(0); p < static_cast<std::uint32_t>(points); ++p) {
    const draco::AttributeValueIndex value = position->mapped_index(p);
    if (value.value() >= position->size())
      throw Problem(where, "its Draco POSITION has no value for point " + std::to_string(p.value()));
    std::memcpy(&out.positions[3 * std::size_t{p.value()}], position->GetAddress(value), 12);
  }
  out.indices.resize(3 * static_cast<std::size_t>(faces));
  for (draco::FaceIndex f(0); f < static_cast<std::uint32_t>(faces); ++f) {
    const draco::Mesh::Face& face = mesh->face(f);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t corner = face[k].value();
      if (corner >= points)
        throw Problem(where, "its Draco face " + std::to_string(f.value()) + " refers to point " + std::to_string(corner) + " of " +
                                 std::to_string(points));
      out.indices[3 * std::size_t{f.value()} + static_cast<std::size_t>(k)] = corner;
    }
  }
  return out;
}

}  // namespace softdeca::avatar_import::gltf
