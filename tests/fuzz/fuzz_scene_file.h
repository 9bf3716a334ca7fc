// The fuzz targets of the scene readers (glTF, FBX): the input written to a file of the
// format's extension and read by read_scene_file, as the command line reads a user's avatar,
// then joined by assemble_avatar. Either step may refuse with std::runtime_error; what they
// return has the properties of fuzz_import_check.h. Limits are small, so that they are reached.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "avatar_file.h"
#include "avatar_source.h"
#include "fuzz_files.h"
#include "fuzz_import_check.h"

// assimp (a system library, not built here) leaks some of what it allocates for a few malformed
// FBX files before it gives up on them; those leaks are assimp's, outside the import's code.
extern "C" const char* __lsan_default_suppressions() { return "leak:libassimp.so\n"; }

namespace softdeca::fuzz {

inline avatar_import::ImportLimits small_import_limits() {
  avatar_import::ImportLimits limits;
  limits.max_file_bytes = 1 << 20;
  limits.max_total_bytes = 2 << 20;
  limits.max_vertices = 4096;
  limits.max_triangles = 8192;
  limits.max_json_bytes = 1 << 20;
  limits.max_json_values = 100000;
  limits.max_nodes = 1000;
  limits.max_instanced_vertices = 8192;
  limits.max_morph_targets = 64;
  limits.max_decoded_bytes = 16 << 20;
  limits.max_shape_files = 64;
  return limits;
}

// Reads `bytes` as <workspace>/avatar.<extension>.
inline void read_scene_bytes(const std::string& tag, const std::string& extension, const uint8_t* data, size_t size) {
  static const std::filesystem::path dir = workspace(tag);
  const std::filesystem::path path = dir / ("avatar." + extension);
  std::error_code ec;
  std::filesystem::remove(path, ec);
  write_file(path, std::string(reinterpret_cast<const char*>(data), size));
  const avatar_import::ImportLimits limits = small_import_limits();
  try {
    avatar_import::SourceScene scene = avatar_import::read_scene_file(path.string(), limits);
    check_scene(scene, limits);
    check_avatar(avatar_import::assemble_avatar(std::move(scene), path.string(), {}, limits), limits);
  } catch (const std::runtime_error&) {
  }
}

}  // namespace softdeca::fuzz
