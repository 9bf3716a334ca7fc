// Which reader a scene file goes to: FBX to assimp (scene_assimp.cpp), glTF to its own reader.
#include "avatar_source.h"
#include "file_format.h"
#include "gltf_reader.h"

namespace softdeca::avatar_import {

SourceScene read_scene_file(const std::string& path, const ImportLimits& limits) {
  return lower_extension(path) == "fbx" ? read_fbx_file(path, limits) : read_gltf(path, limits);
}

}  // namespace softdeca::avatar_import
