// Builds without assimp (cross builds): FBX avatars are refused with the reason.
#include <stdexcept>

#include "avatar_source.h"

namespace softdeca::avatar_import {

bool fbx_files_supported() { return false; }

SourceScene read_fbx_file(const std::string& path, const ImportLimits&) {
  throw std::runtime_error(path + ": this softdeca was built without assimp, which FBX avatars need; give the avatar as glTF "
                           "(.gltf, .glb, .vrm) or as an avatar folder (neutral.obj, blendshapes/<name>.obj) instead");
}

}  // namespace softdeca::avatar_import
