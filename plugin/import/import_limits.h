// What the import accepts from a user's avatar file, whoever wrote it: every size, count and
// depth is checked against these before anything of that size is allocated, so memory stays
// within a small multiple of the input plus a constant and time within the vertex and
// triangle bounds (docs/security.md lists them and what each refusal says).
#pragma once

#include <cstddef>
#include <cstdint>

#include "softdeca/softdeca.h"

namespace softdeca::avatar_import {

struct ImportLimits {
  std::uint64_t max_file_bytes = std::uint64_t{1} << 30;     // one file: the avatar, a buffer, an OBJ
  std::uint64_t max_total_bytes = std::uint64_t{2} << 30;    // everything one import reads, together
  std::size_t max_vertices = SOFTDECA_MAX_AVATAR_VERTICES;   // one mesh, and the included meshes together
  std::size_t max_triangles = 3 * std::size_t{SOFTDECA_MAX_AVATAR_VERTICES};
  std::uint64_t max_json_bytes = 64u << 20;                  // a glTF's JSON
  std::size_t max_json_values = 2000000;                     // values in that JSON
  int max_json_depth = 64;                                   // its nesting
  std::size_t max_nodes = 100000;                            // scene nodes
  int max_node_depth = 256;                                  // their nesting
  std::uint64_t max_instanced_vertices = 2 * std::uint64_t{SOFTDECA_MAX_AVATAR_VERTICES};  // a mesh used by several nodes counts each time
  std::size_t max_morph_targets = 1024;                      // per mesh
  std::uint64_t max_decoded_bytes = std::uint64_t{1} << 30;  // all vertex data decoded (accessors, compression), together
  std::size_t max_shape_files = 4096;                        // files in an avatar folder's blendshapes/
  int max_fbx_depth = 64;                                    // an FBX file's nodes (binary) or braces (ASCII) nested
  std::uint64_t decoded_base_bytes = std::uint64_t{200} << 20;  // decoded data beyond twice the input

  // What one import may decode from `input_bytes` read (vertex data, decompressed arrays,
  // compressed meshes' tables): twice that plus a constant, within max_decoded_bytes, so a small
  // file cannot expand into much memory however it repeats, shares or compresses its data.
  std::uint64_t decoded_budget(std::uint64_t input_bytes) const {
    const std::uint64_t twice = input_bytes > max_decoded_bytes ? max_decoded_bytes : 2 * input_bytes;
    return twice + decoded_base_bytes < max_decoded_bytes ? twice + decoded_base_bytes : max_decoded_bytes;
  }
};

}  // namespace softdeca::avatar_import
