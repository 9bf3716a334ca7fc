// OBJ meshes as the import reads them: `v` and `f` records of a file already read whole (f may
// use v/vt/vn and negative indices, polygons are fan-triangulated), every count bounded by the
// limits before it grows, every index checked against the vertices it names.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "import_limits.h"

namespace softdeca::avatar_import {

struct ObjMesh {
  std::vector<float> vertices;          // xyz
  std::vector<std::int32_t> triangles;  // polygons fan-triangulated
  std::size_t vertex_count() const { return vertices.size() / 3; }
};

// Parses OBJ text; `name` names it in errors ("<name>:<line>: bad vertex", "<name>: more than N
// triangles", "<name>:<line>: face index 9 beyond the 8 vertices"). Throws std::runtime_error.
ObjMesh parse_obj(const std::string& text, const std::string& name, const ImportLimits& limits = {});

// A file the user named (read_named_file's checks), parsed.
ObjMesh read_obj(const std::string& path, const ImportLimits& limits = {});

}  // namespace softdeca::avatar_import
