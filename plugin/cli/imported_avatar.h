// The import layer's avatar (plugin/import) under the names the command line uses.
#pragma once

#include "avatar_file.h"
#include "obj_reader.h"
#include "shape_names.h"

namespace softdeca::cli {

using avatar_import::AvatarFile;
using avatar_import::AvatarPart;
using avatar_import::avatar_mesh_sha256;
using avatar_import::ImportLimits;
using avatar_import::LeftOutMesh;
using avatar_import::read_avatar_file;
using avatar_import::ShapeNames;
using avatar_import::ShapeSource;
using avatar_import::UnusedName;

}  // namespace softdeca::cli
