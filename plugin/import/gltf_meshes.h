// One glTF mesh as the import takes it: the positions of its triangle primitives (modes 4, 5 and
// 6: triangle lists, strips and fans as lists) joined in primitive order, each primitive's
// indices offset by the vertices before it; primitives that share their vertex data (one POSITION
// accessor and the same target accessors, as exporters write a mesh of several materials) share
// their vertices; points and lines left out. Morph targets become
// shapes of position deltas under the names the file gives them (mesh.extras.targetNames, else
// the first primitive's extras.targetNames, else each target's extras.name); a target without
// POSITION moves nothing. KHR_draco_mesh_compression primitives are decoded (gltf_draco.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "avatar_source.h"
#include "gltf_accessors.h"
#include "import_limits.h"

namespace softdeca::avatar_import::gltf {

struct MeshData {
  std::string name;   // mesh.name, "" when it has none
  std::string label;  // how errors name it: "mesh 'Head'", or "meshes[3]" when it has no name
  std::vector<float> vertices;
  std::vector<std::int32_t> triangles;
  std::vector<SourceShape> shapes;
};

// The vertices meshes[index]'s triangle primitives declare (their POSITION accessors' counts,
// shared vertex data once), known before anything is decoded: what bounds instancing.
std::uint64_t declared_vertices(Document& doc, std::size_t index);

// Reads meshes[index]. Throws Problem naming the mesh (and primitive): more vertices, triangles
// or morph targets than `limits` allow, primitives whose targets disagree, an index not below its
// primitive's vertex count, a target of another vertex count.
MeshData read_mesh(AccessorReader& reader, std::size_t index, const ImportLimits& limits);

}  // namespace softdeca::avatar_import::gltf
