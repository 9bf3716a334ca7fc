// EXT_meshopt_compression: a buffer view stored compressed by meshoptimizer's codecs (vertex
// attributes, triangle lists, index sequences) and optionally filtered (octahedral normals,
// quaternions, exponential floats). Decoded with the system's libmeshoptimizer where the build
// found it; a build without it refuses such views by name.
#pragma once

#include <string>
#include <string_view>

#include "gltf_document.h"

namespace softdeca::avatar_import::gltf {

bool meshopt_supported();

// Decodes `compressed` as `view` describes (the document has checked the mode, stride, count
// and filter against the extension's rules) into `out`, view.count * view.stride bytes the
// caller allocated. Throws Problem at `where` when the data does not decode.
void decode_meshopt(const MeshoptView& view, std::string_view compressed, unsigned char* out, const std::string& where);

}  // namespace softdeca::avatar_import::gltf
