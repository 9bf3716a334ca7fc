// Avatar folders: a neutral OBJ and one OBJ per shape, read through the folder (InputFolder: no
// link followed, no FIFO opened). Only the shapes the names choose are read, so a folder costs
// at most 53 meshes whatever else it holds.
#include <algorithm>
#include <stdexcept>

#include "avatar_source.h"
#include "input_files.h"
#include "obj_reader.h"

namespace softdeca::avatar_import {

namespace {
ObjMesh read_member(const InputFolder& folder, const std::string& relative, const ImportLimits& limits) {
  return parse_obj(folder.read(relative, limits.max_file_bytes, "an OBJ file"), folder.path() + "/" + relative, limits);
}

std::string folder_name(const std::string& dir) {
  std::string name = dir;
  while (name.size() > 1 && (name.back() == '/' || name.back() == '\\')) name.pop_back();
  const std::size_t slash = name.find_last_of("/\\");
  return slash == std::string::npos ? name : name.substr(slash + 1);
}
}  // namespace

SourceScene read_avatar_folder(const std::string& dir, const ShapeNames& names, const ImportLimits& limits) {
  SourceScene scene;
  scene.format = "avatar folder";
  scene.vertex_order = "as in neutral.obj";
  const InputFolder folder(dir);
  SourceMesh mesh;
  mesh.name = folder_name(dir);
  const ObjMesh neutral = read_member(folder, "neutral.obj", limits);
  mesh.vertices = neutral.vertices;
  mesh.triangles = neutral.triangles;

  std::vector<std::string> files;  // shape names, sorted: the first of two that give a shape wins
  if (folder.has_folder("blendshapes"))
    for (const std::string& file : folder.list("blendshapes", limits.max_shape_files))
      if (file.size() > 4 && file.compare(file.size() - 4, 4, ".obj") == 0) files.push_back(file.substr(0, file.size() - 4));
  std::sort(files.begin(), files.end());
  const ShapeChoice choice = choose_shapes(files, names);
  std::vector<bool> read(files.size(), false);
  for (const int c : choice.chosen)
    if (c >= 0) read[static_cast<std::size_t>(c)] = true;
  for (std::size_t i = 0; i < files.size(); ++i) {
    SourceShape shape{files[i], {}};
    if (read[i]) {
      const std::string relative = "blendshapes/" + files[i] + ".obj";
      const ObjMesh target = read_member(folder, relative, limits);
      if (target.vertices.size() != mesh.vertices.size())
        throw std::runtime_error(dir + "/" + relative + ": shape '" + files[i] + "' has " + std::to_string(target.vertex_count()) +
                                 " vertices, neutral.obj " + std::to_string(mesh.vertex_count()));
      shape.deltas.resize(target.vertices.size());
      for (std::size_t k = 0; k < shape.deltas.size(); ++k) shape.deltas[k] = target.vertices[k] - mesh.vertices[k];
    }
    mesh.shapes.push_back(std::move(shape));
  }
  scene.meshes.push_back(std::move(mesh));
  return scene;
}

}  // namespace softdeca::avatar_import
