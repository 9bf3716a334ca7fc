// assimp (5.2) reads a glTF morph target whose vertex count differs from its mesh's as a target
// that moves nothing, with a warning no caller sees. The file's JSON states both counts: they
// are compared here before assimp reads the file, so such a shape is an error, not a lost shape.
#pragma once

#include <string>

#include "avatar_source.h"

namespace softdeca::avatar_import {

// Throws std::runtime_error "<path>: mesh '<name>': shape '<target>' has N vertices, the mesh M".
// A JSON part it cannot read is left to assimp, which reports it.
void check_gltf_targets(const std::string& bytes, const std::string& path);

}  // namespace softdeca::avatar_import
