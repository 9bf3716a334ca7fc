// glTF 2.0 avatars (.gltf, and .glb and .vrm in the binary container) read for the import,
// written for the format and for files nobody here wrote: every mesh instance of the file's
// scene, each in its mesh's own coordinates with its node's placing transform, its triangle
// primitives joined in the file's vertex order, morph targets as shapes of position deltas
// under the file's names, and VRM expressions as shapes of their own (gltf_vrm.h). Handles
// sparse and buffer-less accessors, KHR_mesh_quantization, EXT_meshopt_compression and
// KHR_draco_mesh_compression (where this build has their decoders), data: URIs and buffers in
// files beside the avatar (read through its folder only). Everything the file states is checked
// against the specification and ImportLimits before memory of that size is allocated.
#pragma once

#include <string>

#include "avatar_source.h"
#include "import_limits.h"

namespace softdeca::avatar_import {

// Throws std::runtime_error "<path>: <place in the file>: <problem>", e.g.
// "avatar.glb: accessors[146]: its sparse indices are not increasing (3 after 7)".
SourceScene read_gltf(const std::string& path, const ImportLimits& limits);

}  // namespace softdeca::avatar_import
