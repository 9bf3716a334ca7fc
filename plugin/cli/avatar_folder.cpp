// Avatar folders: a neutral OBJ and one OBJ per shape. Only the shapes the names choose are
// read, so a folder costs at most 53 meshes whatever else it holds.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "avatar_source.h"
#include "mesh_io.h"

namespace softdeca::cli {

namespace {
constexpr std::size_t kMaxShapeFiles = 4096;

ObjMesh read_bounded_obj(const std::string& path, const AvatarLimits& limits) {
  require_file_within(path, limits);
  ObjMesh mesh = read_obj(path);
  if (mesh.vertex_count() > limits.max_vertices)
    throw std::runtime_error(path + ": " + std::to_string(mesh.vertex_count()) + " vertices, more than the " +
                             std::to_string(limits.max_vertices) + " an avatar may have");
  return mesh;
}
}  // namespace

SourceScene read_avatar_folder(const std::string& dir, const ShapeNames& names, const AvatarLimits& limits) {
  namespace fs = std::filesystem;
  SourceScene scene;
  scene.format = "avatar folder";
  scene.vertex_order = "as in neutral.obj";
  SourceMesh mesh;
  const fs::path folder(dir);
  mesh.name = folder.filename().empty() ? folder.parent_path().filename().string() : folder.filename().string();
  const ObjMesh neutral = read_bounded_obj((folder / "neutral.obj").string(), limits);
  mesh.vertices = neutral.vertices;
  mesh.triangles = neutral.triangles;

  std::vector<std::string> files;  // shape names, sorted: the first of two that give a shape wins
  const fs::path shapes = folder / "blendshapes";
  std::error_code error;
  if (fs::is_directory(shapes, error)) {
    for (const auto& entry : fs::directory_iterator(shapes, error)) {
      if (entry.path().extension() != ".obj") continue;
      if (files.size() == kMaxShapeFiles)
        throw std::runtime_error(shapes.string() + ": more than " + std::to_string(kMaxShapeFiles) + " shape files");
      files.push_back(entry.path().stem().string());
    }
    if (error) throw std::runtime_error("cannot list " + shapes.string() + ": " + error.message());
  }
  std::sort(files.begin(), files.end());
  const ShapeChoice choice = choose_shapes(files, names);
  std::vector<bool> read(files.size(), false);
  for (const int c : choice.chosen)
    if (c >= 0) read[static_cast<std::size_t>(c)] = true;
  for (std::size_t i = 0; i < files.size(); ++i) {
    SourceShape shape{files[i], {}};
    if (read[i]) {
      const std::string path = (shapes / (files[i] + ".obj")).string();
      const ObjMesh target = read_bounded_obj(path, limits);
      if (target.vertices.size() != mesh.vertices.size())
        throw std::runtime_error(path + ": shape '" + files[i] + "' has " + std::to_string(target.vertex_count()) +
                                 " vertices, neutral.obj " + std::to_string(mesh.vertex_count()));
      shape.deltas.resize(target.vertices.size());
      for (std::size_t k = 0; k < shape.deltas.size(); ++k) shape.deltas[k] = target.vertices[k] - mesh.vertices[k];
    }
    mesh.shapes.push_back(std::move(shape));
  }
  scene.meshes.push_back(std::move(mesh));
  return scene;
}

}  // namespace softdeca::cli
