// A user's avatar file as its readers hand it over, before any mesh is chosen: every mesh of the
// file in its own local coordinates with its own shapes under the rig's own names, and the
// transform that places it in the file's common space. avatar_file.h chooses and joins them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "import_limits.h"
#include "shape_names.h"
#include "softdeca/softdeca.h"

namespace softdeca::avatar_import {

struct SourceShape {
  std::string name;           // the rig's own name, as the file spells it
  std::vector<float> deltas;  // vertex_count x 3, local coordinates; empty: left unread
};

struct SourceMesh {
  std::string name;  // the node's name, else the mesh's (glTF: else the nearest named ancestor's)
  std::vector<float> vertices;          // local coordinates, the file's vertex order
  std::vector<std::int32_t> triangles;  // points and lines dropped
  std::vector<SourceShape> shapes;
  double transform[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // row-major, local -> file space
  std::size_t vertex_count() const { return vertices.size() / 3; }
};

struct SourceScene {
  std::string format;         // "glTF 2.0", "FBX", "avatar folder"
  std::string declared_unit;  // what the file says about its unit, "" when it says nothing
  double declared_metres_per_unit = 0;  // 0: not declared
  std::string vertex_order;   // how the vertex order relates to the file's
  std::vector<SourceMesh> meshes;
};

// glTF 2.0 (.gltf, .glb, .vrm: gltf_reader.h) or FBX (read_fbx_file), by the file's extension.
// Throws std::runtime_error naming the file, and the mesh or the place in the file at fault.
SourceScene read_scene_file(const std::string& path, const ImportLimits& limits);

// FBX through assimp, triangulated only (each mesh keeps its vertex order; the per-corner
// vertices assimp makes are welded back, avatar_weld.h).
SourceScene read_fbx_file(const std::string& path, const ImportLimits& limits);

// An avatar folder (avatar_file.h): neutral.obj and the shapes of blendshapes/ that `names`
// chooses (choose_shapes), one mesh; the other shape files are listed by name, unread.
SourceScene read_avatar_folder(const std::string& dir, const ShapeNames& names, const ImportLimits& limits);

// False when this build has no assimp: FBX files are then refused, saying so.
bool fbx_files_supported();

}  // namespace softdeca::avatar_import
