// A user's own avatar read into the one mesh the fit takes (softdeca_avatar_mesh): the meshes of
// the file that carry at least one ARKit shape, each placed in the file's common space by its
// node's transform and joined in file order, with the 52 ARKit shapes as deltas. Meshes without
// any ARKit shape (hair, clothes, a body that no shape moves when it is a mesh of its own) are
// listed, not included. The file's unit is kept (the fit reads the unit off the shapes).
//
// MESH is a glTF 2.0 file (.gltf, .glb, .vrm), an FBX file, or an avatar folder:
//   <dir>/neutral.obj                 the neutral mesh
//   <dir>/blendshapes/<name>.obj      one OBJ per shape, the neutral's vertex count and order;
//                                     <name> is the rig's own name (eyeBlinkLeft, eyeBlink_L, ...)
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "avatar_source.h"
#include "shape_names.h"
#include "softdeca/softdeca.h"

namespace softdeca::avatar_import {

struct AvatarPart {
  std::string name;
  std::size_t first_vertex = 0, vertex_count = 0;
  std::size_t first_triangle = 0, triangle_count = 0;
  double transform[16];  // row-major: the part's own coordinates -> the common space
  bool mirrored = false;  // the transform mirrors: the common mesh's triangles are turned over
};

struct LeftOutMesh {
  std::string name, reason;
  std::size_t vertex_count = 0;
};

struct ShapeSource {  // where one ARKit shape of one part came from
  std::string part, rig_name;
};

struct UnusedName {
  std::string mesh, name, reason;
};

struct AvatarFile {
  std::string path, format, declared_unit, vertex_order;
  double declared_metres_per_unit = 0;  // 0: the file does not say
  std::string names_file;               // the mapping file used, "" for the rule alone
  std::vector<AvatarPart> parts;
  std::vector<float> neutral;            // N x 3, common space
  std::vector<std::int32_t> triangles;   // over all parts, outward as in the file
  std::vector<float> blendshapes;        // 52 x N x 3 deltas, canonical order, zeros where missing
  std::array<std::vector<ShapeSource>, 52> shape_sources;
  std::vector<LeftOutMesh> left_out;
  std::vector<UnusedName> names_not_used;

  std::size_t vertex_count() const { return neutral.size() / 3; }
  std::size_t shape_count() const;  // ARKit shapes some part has
  // A view for the C ABI; valid while this object lives unchanged.
  softdeca_avatar_mesh abi_mesh() const;
};

// Reads MESH (kind by extension, or a folder); `names` maps the rig's names (ShapeNames: the rule
// and an optional mapping file). Throws std::runtime_error naming the file, and the mesh where
// one is at fault: unreadable or truncated files, NaN vertices, shapes of another vertex count,
// files or meshes beyond the limits, no mesh with an ARKit shape.
AvatarFile read_avatar_file(const std::string& path, const ShapeNames& names = {}, const ImportLimits& limits = {});

// The chosen meshes of a scene joined into one (what read_avatar_file does after reading).
AvatarFile assemble_avatar(SourceScene scene, const std::string& path, const ShapeNames& names, const ImportLimits& limits);

// SHA-256 of the mesh as read (its neutral, triangles and 52 shapes): names the exact mesh a
// fit was made for, however it was stored.
std::string avatar_mesh_sha256(const AvatarFile& avatar);

}  // namespace softdeca::avatar_import
