#include "gltf_reader.h"

#include <algorithm>
#include <map>
#include <new>
#include <stdexcept>

#include "core/error.h"
#include "file_format.h"
#include "gltf_accessors.h"
#include "gltf_buffers.h"
#include "gltf_container.h"
#include "gltf_document.h"
#include "gltf_meshes.h"
#include "gltf_nodes.h"
#include "gltf_vrm.h"
#include "input_files.h"

namespace softdeca::avatar_import {

namespace {
using namespace gltf;

std::string folder_of(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// glTF 2.0 only: asset.version "2.x", and no minVersion beyond 2.0.
void require_version(const Document& doc) {
  const auto asset = doc.root().optional_object("asset");
  if (!asset) throw Problem("", "its JSON has no asset object: not a glTF 2.0 file");
  const std::string version = asset->string_or("version", "");
  if (version.empty()) asset->fail("has no version");
  if (version.substr(0, version.find('.')) != "2") throw Problem(asset->at("version"), "'" + version + "': only glTF 2.0 is read");
  const std::string min = asset->string_or("minVersion", "2.0");
  if (min != "2.0" && min != "2") throw Problem(asset->at("minVersion"), "'" + min + "' asks for more than glTF 2.0");
}

// Copies what several instances share; the last instance of a mesh takes it.
SourceMesh instance_mesh(MeshData& data, bool last_use, DecodeBudget& budget, const std::string& name) {
  SourceMesh mesh;
  if (last_use) {
    mesh.vertices = std::move(data.vertices);
    mesh.triangles = std::move(data.triangles);
    mesh.shapes = std::move(data.shapes);
    return mesh;
  }
  std::uint64_t bytes = sizeof(SourceMesh) + 4 * (data.vertices.size() + data.triangles.size());
  for (const SourceShape& s : data.shapes) bytes += sizeof(SourceShape) + s.name.size() + 4 * s.deltas.size();
  budget.take(bytes, "mesh instance '" + name + "'");
  mesh.vertices = data.vertices;
  mesh.triangles = data.triangles;
  mesh.shapes = data.shapes;
  return mesh;
}

SourceScene read(const std::string& path, const ImportLimits& limits) {
  const std::string bytes = read_named_file(path, limits.max_file_bytes, "an avatar file");
  const FileFormat format = agreed_format(path, bytes);
  if (format == FileFormat::fbx) throw Problem("", "an FBX file, not glTF");
  const Container container = split_container(bytes, format == FileFormat::gltf_binary, limits.max_json_bytes);
  bundle::JsonLimits json_limits;
  json_limits.max_depth = limits.max_json_depth;
  json_limits.max_values = limits.max_json_values;
  Document doc(Json::parse(container.json, json_limits));
  require_version(doc);

  DecodeBudget budget(limits, bytes.size());
  BinaryData data(doc, container, bytes, folder_of(path), limits, budget, bytes.size());
  AccessorReader reader(doc, data, budget);
  const std::vector<Instance> instances = scene_instances(reader, limits);
  const Expressions expressions(doc);

  std::map<std::size_t, std::size_t> uses;
  for (const Instance& i : instances) ++uses[i.mesh];
  std::map<std::size_t, MeshData> meshes;
  SourceScene scene;
  scene.format = format_name(format);
  scene.declared_unit = "metre (glTF 2.0)";
  scene.declared_metres_per_unit = 1;
  scene.vertex_order = "as in the file's vertex buffers";
  for (const Instance& instance : instances) {
    auto it = meshes.find(instance.mesh);
    if (it == meshes.end()) it = meshes.emplace(instance.mesh, read_mesh(reader, instance.mesh, limits)).first;
    const std::string label_of_mesh = it->second.label;
    const bool last_use = --uses[instance.mesh] == 0;
    SourceMesh out = instance_mesh(it->second, last_use, budget, instance.name);
    if (last_use) meshes.erase(it);
    out.name = instance.name;
    std::copy(instance.transform, instance.transform + 16, out.transform);
    expressions.add_shapes(instance.mesh, instance.node, label_of_mesh, out, limits.max_morph_targets, budget);
    scene.meshes.push_back(std::move(out));
  }
  return scene;
}
}  // namespace

SourceScene read_gltf(const std::string& path, const ImportLimits& limits) {
  try {
    return read(path, limits);
  } catch (const Problem& p) {
    throw std::runtime_error(path + ": " + p.what());
  } catch (const Error& e) {  // the JSON parser's: "JSON: nesting deeper than 64 at byte 65"
    throw std::runtime_error(path + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(path + ": not enough memory to read it");
  } catch (const std::length_error&) {
    throw std::runtime_error(path + ": not enough memory to read it");
  }
}

}  // namespace softdeca::avatar_import
