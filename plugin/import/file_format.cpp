#include "file_format.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <stdexcept>

namespace softdeca::avatar_import {

namespace {
constexpr char kFbxBinaryMagic[] = "Kaydara FBX Binary  ";

bool starts_with(const std::string& bytes, const char* prefix) {
  const std::size_t n = std::strlen(prefix);
  return bytes.size() >= n && bytes.compare(0, n, prefix) == 0;
}

// The first character that is not white space or a UTF-8 byte order mark.
std::size_t text_start(const std::string& bytes) {
  std::size_t i = starts_with(bytes, "\xEF\xBB\xBF") ? 3 : 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  return i;
}

// ASCII FBX: comments start with ';', and its first record is FBXHeaderExtension.
bool looks_like_ascii_fbx(const std::string& bytes) {
  const std::string head = bytes.substr(0, 4096);
  return head.find("FBXHeaderExtension") != std::string::npos && head.find('\0') == std::string::npos;
}

std::string what_it_is(const std::string& bytes) {
  if (starts_with(bytes, "glTF")) return "a binary glTF";
  if (starts_with(bytes, kFbxBinaryMagic)) return "a binary FBX";
  if (looks_like_ascii_fbx(bytes)) return "an ASCII FBX";
  const std::size_t t = text_start(bytes);
  if (t < bytes.size() && bytes[t] == '{') return "JSON";
  if (starts_with(bytes, "ply")) return "a PLY file";
  if (bytes.substr(0, 4096).find("\nv ") != std::string::npos || starts_with(bytes, "v ") || starts_with(bytes, "#"))
    return "text (an OBJ?)";
  return "none of glTF, binary glTF or FBX";
}
}  // namespace

std::string lower_extension(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find_first_of("/\\", dot) != std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool is_avatar_file_name(const std::string& path) {
  const std::string ext = lower_extension(path);
  return ext == "gltf" || ext == "glb" || ext == "vrm" || ext == "fbx";
}

FileFormat agreed_format(const std::string& path, const std::string& bytes) {
  const std::string ext = lower_extension(path);
  const auto refuse = [&](const char* expected) -> std::runtime_error {
    return std::runtime_error(path + ": its name says " + expected + ", but its contents are " + what_it_is(bytes));
  };
  if (ext == "glb" || ext == "vrm") {
    if (!starts_with(bytes, "glTF")) throw refuse("binary glTF");
    return FileFormat::gltf_binary;
  }
  if (ext == "gltf") {
    const std::size_t t = text_start(bytes);
    if (t >= bytes.size() || bytes[t] != '{') throw refuse("glTF (JSON)");
    return FileFormat::gltf_json;
  }
  if (ext == "fbx") {
    if (!starts_with(bytes, kFbxBinaryMagic) && !looks_like_ascii_fbx(bytes)) throw refuse("FBX");
    return FileFormat::fbx;
  }
  throw std::runtime_error(path + ": not an avatar (a .gltf, .glb, .vrm or .fbx file, or a folder with neutral.obj)");
}

const char* format_name(FileFormat format) {
  switch (format) {
    case FileFormat::gltf_json:
    case FileFormat::gltf_binary: return "glTF 2.0";
    case FileFormat::fbx: return "FBX";
  }
  return "";
}

}  // namespace softdeca::avatar_import
