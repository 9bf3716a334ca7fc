#include "gltf_targets.h"

#include <cstdint>
#include <stdexcept>

#include "bundle/json.h"

namespace softdeca::avatar_import {

namespace {
using runtime::Json;

// The JSON of a .gltf, or the first chunk of a binary glTF (.glb, .vrm); "" when there is none.
std::string gltf_json(const std::string& bytes) {
  if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0) return bytes;
  std::uint32_t length = 0;
  for (int k = 3; k >= 0; --k) length = (length << 8) | static_cast<unsigned char>(bytes[12 + static_cast<std::size_t>(k)]);
  if (bytes.compare(16, 4, "JSON") != 0 || length > bytes.size() - 20) return "";  // a length the file cannot hold
  return bytes.substr(20, length);
}

// accessors[index].count, or -1 where the file does not say.
long long accessor_count(const Json& root, const Json& index) {
  if (!index.is_number() || !root.has("accessors")) return -1;
  const Json& accessors = root.at("accessors", "accessors");
  if (!accessors.is_array()) return -1;
  const long long i = index.integer("accessor");
  if (i < 0 || static_cast<std::size_t>(i) >= accessors.array("accessors").size()) return -1;
  const Json& a = accessors.array("accessors")[static_cast<std::size_t>(i)];
  return a.has("count") && a.at("count", "count").is_number() ? a.at("count", "count").integer("count") : -1;
}

const Json* member(const Json& object, const char* key) { return object.has(key) ? &object.at(key, key) : nullptr; }

void check_mesh(const std::string& path, const Json& root, const Json& mesh, std::size_t index) {
  const Json* name = member(mesh, "name");
  const std::string mesh_name = name && name->is_string() ? name->string("name") : "#" + std::to_string(index);
  const Json* extras = member(mesh, "extras");
  const Json* names = extras ? member(*extras, "targetNames") : nullptr;
  const Json* primitives = member(mesh, "primitives");
  if (!primitives || !primitives->is_array()) return;
  for (const Json& primitive : primitives->array("primitives")) {
    const Json* attributes = member(primitive, "attributes");
    const Json* targets = member(primitive, "targets");
    if (!attributes || !targets || !targets->is_array() || !member(*attributes, "POSITION")) continue;
    const long long vertices = accessor_count(root, attributes->at("POSITION", "POSITION"));
    const auto& list = targets->array("targets");
    for (std::size_t t = 0; t < list.size(); ++t) {
      const Json* position = member(list[t], "POSITION");
      const long long count = position ? accessor_count(root, *position) : -1;
      if (vertices < 0 || count < 0 || count == vertices) continue;
      std::string target = "#" + std::to_string(t);
      if (names && names->is_array() && t < names->array("targetNames").size() && names->array("targetNames")[t].is_string())
        target = names->array("targetNames")[t].string("targetName");
      throw std::runtime_error(path + ": mesh '" + mesh_name + "': shape '" + target + "' has " + std::to_string(count) +
                               " vertices, the mesh " + std::to_string(vertices));
    }
  }
}
}  // namespace

void check_gltf_targets(const std::string& bytes, const std::string& path) {
  Json root;
  try {
    root = Json::parse(gltf_json(bytes));
  } catch (const std::exception&) {
    return;  // not JSON we can read: assimp says what is wrong
  }
  const Json* meshes = member(root, "meshes");
  if (!meshes || !meshes->is_array()) return;
  for (std::size_t m = 0; m < meshes->array("meshes").size(); ++m) {
    const Json& mesh = meshes->array("meshes")[m];
    if (mesh.is_object()) check_mesh(path, root, mesh, m);
  }
}

}  // namespace softdeca::avatar_import
