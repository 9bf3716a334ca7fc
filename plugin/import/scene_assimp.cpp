// FBX avatars through assimp (glTF has a reader of its own, gltf_reader.h). Only triangulation
// runs (no joining of identical vertices, which would reorder them): each mesh keeps the vertex
// order its file gives, so a point cache written in that order loads onto the mesh. assimp reads
// FBX one vertex per polygon corner; those corners are welded back into the file's vertices
// (avatar_weld.h).
#include <assimp/Exceptional.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <stdexcept>

#include "avatar_source.h"
#include "avatar_weld.h"
#include "fbx_bounds.h"
#include "file_format.h"
#include "input_files.h"

namespace softdeca::avatar_import {

namespace {
struct Reader {
  const std::string& path;
  const ImportLimits& limits;
  const aiScene& scene;
  SourceScene out;

  std::string mesh_name(const aiNode& node, unsigned k) const {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[k]];
    const std::string node_name = node.mName.C_Str(), own = mesh.mName.C_Str();
    if (node_name.empty()) return own;
    if (node.mNumMeshes == 1) return node_name;
    return node_name + "/" + (own.empty() ? std::to_string(k) : own);
  }

  SourceMesh read_mesh(const aiMesh& mesh, std::string name, const aiMatrix4x4& global) const {
    if (mesh.mNumVertices > limits.max_vertices)
      throw std::runtime_error(path + ": mesh '" + name + "': " + std::to_string(mesh.mNumVertices) + " vertices, more than the " +
                               std::to_string(limits.max_vertices) + " an avatar may have");
    SourceMesh out;
    out.name = std::move(name);
    out.vertices.resize(3 * std::size_t{mesh.mNumVertices});
    for (unsigned i = 0; i < mesh.mNumVertices; ++i)
      for (unsigned c = 0; c < 3; ++c) out.vertices[3 * i + c] = mesh.mVertices[i][c];
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      for (unsigned c = 0; c < 3; ++c) out.triangles.push_back(static_cast<std::int32_t>(face.mIndices[c]));
    }
    // assimp stores morph targets as whole positions; the fit takes deltas.
    for (unsigned a = 0; a < mesh.mNumAnimMeshes; ++a) {
      const aiAnimMesh& target = *mesh.mAnimMeshes[a];
      SourceShape shape{target.mName.C_Str(), {}};
      if (!target.HasPositions()) {
        shape.deltas.assign(out.vertices.size(), 0.0f);  // a target of normals alone moves nothing
      } else if (target.mNumVertices <= limits.max_vertices) {
        shape.deltas.resize(3 * std::size_t{target.mNumVertices});
        for (unsigned i = 0; i < target.mNumVertices; ++i)
          for (unsigned c = 0; c < 3; ++c)
            shape.deltas[3 * i + c] = target.mVertices[i][c] - (i < mesh.mNumVertices ? mesh.mVertices[i][c] : 0.0f);
      }
      out.shapes.push_back(std::move(shape));
    }
    const ai_real* m = &global.a1;
    std::copy(m, m + 16, out.transform);
    return out;
  }

  void walk(const aiNode& node, const aiMatrix4x4& parent, unsigned depth) {
    if (depth > 1000) throw std::runtime_error(path + ": nodes nested more than 1000 deep");
    const aiMatrix4x4 global = parent * node.mTransformation;
    for (unsigned k = 0; k < node.mNumMeshes; ++k) {
      if (node.mMeshes[k] >= scene.mNumMeshes) throw std::runtime_error(path + ": a node refers to a mesh that does not exist");
      out.meshes.push_back(read_mesh(*scene.mMeshes[node.mMeshes[k]], mesh_name(node, k), global));
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) walk(*node.mChildren[c], global, depth + 1);
  }
};

// FBX says how many centimetres a unit is (UnitScaleFactor); assimp keeps the raw units and
// passes the factor on as metadata.
void declared_unit(const aiScene& scene, SourceScene& out) {
  double centimetres = 0;
  float as_float = 0;
  if (!scene.mMetaData) return;
  if (scene.mMetaData->Get("UnitScaleFactor", as_float)) centimetres = as_float;
  else if (!scene.mMetaData->Get("UnitScaleFactor", centimetres)) return;
  if (!(centimetres > 0)) return;
  char text[96];
  std::snprintf(text, sizeof text, "%g cm (FBX UnitScaleFactor %g)", centimetres, centimetres);
  out.declared_unit = text;
  out.declared_metres_per_unit = centimetres / 100.0;
}
constexpr const char* kTooLarge = "too large to read: not enough memory";
constexpr const char* kDamaged = "its structure is damaged (the reader failed inside it)";

// Why assimp failed, in the user's terms: its own messages ("FBX-Parser ...") pass; a C++
// library's ("std::bad_alloc", "vector::_M_range_check") do not.
std::string reader_failure(const std::exception_ptr& failure, const std::string& otherwise) {
  if (!failure) return otherwise;
  try {
    std::rethrow_exception(failure);
  } catch (const std::bad_alloc&) {
    return kTooLarge;
  } catch (const DeadlyErrorBase& e) {
    return e.what();
  } catch (...) {
    return kDamaged;
  }
}

// assimp's parse of `bytes`; throws std::runtime_error naming the file and why, never a C++
// library's own text.
const aiScene* parse(Assimp::Importer& importer, const std::string& bytes, const std::string& path) {
  const std::string what = path + ": not a readable FBX file (";
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), aiProcess_ValidateDataStructure | aiProcess_Triangulate, "fbx");
  } catch (...) {
    throw std::runtime_error(what + reader_failure(std::current_exception(), kDamaged) + ")");
  }
  if (!scene || !scene->mRootNode) throw std::runtime_error(what + reader_failure(importer.GetException(), importer.GetErrorString()) + ")");
  return scene;
}

SourceScene read_fbx(const std::string& path, const ImportLimits& limits) {
  // The file is read once, checked on its open descriptor; assimp parses those bytes once they
  // pass the scan (fbx_bounds.h): assimp trusts what a file declares.
  const std::string bytes = read_named_file(path, limits.max_file_bytes, "an avatar file");
  if (agreed_format(path, bytes) != FileFormat::fbx) throw std::runtime_error(path + ": not an FBX file");
  const FbxScan scan = scan_fbx(bytes, path, limits);
  Assimp::Importer importer;
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);  // one node per FBX model
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_ANIMATIONS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_TEXTURES, false);
  const aiScene* scene = parse(importer, bytes, path);
  Reader reader{path, limits, *scene, {}};
  reader.out.format = "FBX";
  reader.out.vertex_order = "the FBX file's vertices in the order its polygons first use them";
  declared_unit(*scene, reader.out);
  reader.walk(*scene->mRootNode, aiMatrix4x4(), 0);
  // assimp leaves out a mesh whose data does not add up, saying nothing.
  if (reader.out.meshes.empty() && scan.meshes > 0)
    throw std::runtime_error(path + ": none of its " + std::to_string(scan.meshes) +
                             " meshes could be read (their data is damaged or empty)");
  for (SourceMesh& mesh : reader.out.meshes) weld_corners(mesh);
  return std::move(reader.out);
}
}  // namespace

bool fbx_files_supported() { return true; }

SourceScene read_fbx_file(const std::string& path, const ImportLimits& limits) {
  try {
    return read_fbx(path, limits);
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(path + ": " + kTooLarge);
  }
}

}  // namespace softdeca::avatar_import
