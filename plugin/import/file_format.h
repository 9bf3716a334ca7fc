// Which reader an avatar file goes to: the format its extension names and its first bytes show
// must agree, or the file is refused (an OBJ or PLY named .glb is not handed to some other parser
// that happens to read it).
#pragma once

#include <string>

namespace softdeca::avatar_import {

enum class FileFormat {
  gltf_json,    // .gltf: JSON text
  gltf_binary,  // .glb, .vrm: the binary glTF container ("glTF" magic)
  fbx,          // .fbx: binary ("Kaydara FBX Binary") or ASCII FBX
};

// The lower-case extension of `path` without its dot, "" when it has none.
std::string lower_extension(const std::string& path);

// Whether `path` names an avatar file by its extension (.gltf, .glb, .vrm, .fbx).
bool is_avatar_file_name(const std::string& path);

// The format of `bytes` read from `path`; throws std::runtime_error naming the file, what its
// extension says and what its contents are when the two disagree.
FileFormat agreed_format(const std::string& path, const std::string& bytes);

const char* format_name(FileFormat format);

}  // namespace softdeca::avatar_import
