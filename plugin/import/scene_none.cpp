// Builds without assimp (cross builds): glTF and FBX avatars are refused with the reason.
#include <stdexcept>

#include "avatar_source.h"

namespace softdeca::avatar_import {

bool scene_files_supported() { return false; }

SourceScene read_scene_file(const std::string& path, const ImportLimits&) {
  throw std::runtime_error(path + ": this softdeca was built without assimp, which glTF and FBX avatars need; "
                           "give an avatar folder (neutral.obj, blendshapes/<name>.obj) instead");
}

}  // namespace softdeca::avatar_import
