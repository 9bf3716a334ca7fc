#include "avatar_file.h"

#include <sys/stat.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "bundle/sha256.h"
#include "file_format.h"

namespace softdeca::avatar_import {

namespace {
using Matrix = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

bool is_directory(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

// Where a mesh goes wrong, in the words of the error messages: "<file>: mesh '<name>': ".
std::string where(const std::string& path, const SourceMesh& mesh) { return path + ": mesh '" + mesh.name + "': "; }

void require_finite(const std::vector<float>& values, const std::string& what) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) throw std::runtime_error(what + "vertex " + std::to_string(i / 3) + " is not finite");
}

// Coordinates an avatar may have in any unit (10,000 km in metres, 10 km in millimetres): a
// vertex beyond is no part of a mesh but a value that would overflow what is computed from it.
constexpr double kMaxCoordinate = 1e7;
// A shape moves a vertex at most this many times the mesh's own size (its bounding box's
// diagonal): a jaw opens by a fraction of the head, a 3e38 delta is no shape.
constexpr double kMaxDeltaOverSize = 2.0;

void require_within(const std::vector<float>& values, const std::string& what) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (std::abs(values[i]) > kMaxCoordinate)
      throw std::runtime_error(what + "vertex " + std::to_string(i / 3) + " lies at " + std::to_string(values[i]) +
                               ", beyond the 1e7 units any avatar spans");
}

double size_of(const std::vector<float>& vertices) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (std::size_t i = 0; i + 2 < vertices.size(); i += 3) {
    const Eigen::Vector3d p = Eigen::Vector3f(vertices.data() + i).cast<double>();
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  return vertices.empty() ? 0.0 : (hi - lo).norm();
}

// The checks of one included mesh before anything is copied.
void check_mesh(const std::string& path, const SourceMesh& mesh, const ShapeChoice& choice) {
  const std::string at = where(path, mesh);
  require_finite(mesh.vertices, at);
  require_within(mesh.vertices, at);
  const double largest_delta = kMaxDeltaOverSize * size_of(mesh.vertices);
  const std::size_t n = mesh.vertex_count();
  for (const std::int32_t t : mesh.triangles)
    if (t < 0 || static_cast<std::size_t>(t) >= n)
      throw std::runtime_error(at + "a triangle refers to vertex " + std::to_string(t) + " of " + std::to_string(n));
  for (const int c : choice.chosen) {
    if (c < 0) continue;
    const SourceShape& shape = mesh.shapes[static_cast<std::size_t>(c)];
    if (shape.deltas.size() != mesh.vertices.size())
      throw std::runtime_error(at + "shape '" + shape.name + "' has " + std::to_string(shape.deltas.size() / 3) +
                               " vertices, the mesh " + std::to_string(n));
    require_finite(shape.deltas, at + "shape '" + shape.name + "': ");
    for (std::size_t i = 0; i + 2 < shape.deltas.size(); i += 3)
      if (Eigen::Vector3f(shape.deltas.data() + i).cast<double>().norm() > largest_delta)
        throw std::runtime_error(at + "shape '" + shape.name + "' moves vertex " + std::to_string(i / 3) + " by " +
                                 std::to_string(Eigen::Vector3f(shape.deltas.data() + i).norm()) + ", more than twice the mesh's own size (" +
                                 std::to_string(size_of(mesh.vertices)) + ")");
  }
  for (const double v : mesh.transform)
    if (!std::isfinite(v)) throw std::runtime_error(at + "its node's transform is not finite");
  const double det = Eigen::Map<const Matrix>(mesh.transform).topLeftCorner<3, 3>().determinant();
  if (!(std::abs(det) > 1e-30)) throw std::runtime_error(at + "its node's transform is singular (a zero scale)");
}

// A unique name for every part: the report and the outputs name parts by it.
std::string unique_name(const std::string& name, std::map<std::string, int>& seen) {
  const std::string base = name.empty() ? "mesh" : name;
  const int n = ++seen[base];
  return n == 1 ? base : base + "#" + std::to_string(n);
}

// Appends one mesh to the avatar, placed by its transform; returns the part.
AvatarPart append(AvatarFile& avatar, const SourceMesh& mesh, const ShapeChoice& choice, std::size_t first_vertex,
                  std::size_t total) {
  AvatarPart part;
  part.first_vertex = first_vertex;
  part.vertex_count = mesh.vertex_count();
  part.first_triangle = avatar.triangles.size() / 3;
  part.triangle_count = mesh.triangles.size() / 3;
  std::copy(mesh.transform, mesh.transform + 16, part.transform);
  const Matrix m = Eigen::Map<const Matrix>(mesh.transform);
  const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
  part.mirrored = linear.determinant() < 0;
  for (std::size_t i = 0; i < part.vertex_count; ++i) {
    const Eigen::Vector3d p = linear * Eigen::Vector3f(mesh.vertices.data() + 3 * i).cast<double>() + m.topRightCorner<3, 1>();
    for (int k = 0; k < 3; ++k) avatar.neutral[3 * (first_vertex + i) + static_cast<std::size_t>(k)] = static_cast<float>(p[k]);
  }
  for (std::size_t t = 0; t < part.triangle_count; ++t) {
    const std::int32_t* tri = mesh.triangles.data() + 3 * t;
    const auto base = static_cast<std::int32_t>(first_vertex);
    // A mirroring transform turns the surface inside out: the corners swap to keep it outward.
    if (part.mirrored) avatar.triangles.insert(avatar.triangles.end(), {base + tri[0], base + tri[2], base + tri[1]});
    else avatar.triangles.insert(avatar.triangles.end(), {base + tri[0], base + tri[1], base + tri[2]});
  }
  for (std::size_t k = 0; k < 52; ++k) {
    if (choice.chosen[k] < 0) continue;
    const SourceShape& shape = mesh.shapes[static_cast<std::size_t>(choice.chosen[k])];
    float* out = avatar.blendshapes.data() + 3 * (k * total + first_vertex);
    for (std::size_t i = 0; i < part.vertex_count; ++i) {
      const Eigen::Vector3d d = linear * Eigen::Vector3f(shape.deltas.data() + 3 * i).cast<double>();
      for (int c = 0; c < 3; ++c) out[3 * i + static_cast<std::size_t>(c)] = static_cast<float>(d[c]);
    }
  }
  return part;
}
}  // namespace

std::size_t AvatarFile::shape_count() const {
  std::size_t n = 0;
  for (const auto& s : shape_sources) n += !s.empty();
  return n;
}

softdeca_avatar_mesh AvatarFile::abi_mesh() const {
  softdeca_avatar_mesh m{};
  m.struct_size = sizeof m;
  m.neutral = neutral.data();
  m.vertex_count = static_cast<uint32_t>(vertex_count());
  m.triangles = triangles.data();
  m.triangle_count = static_cast<uint32_t>(triangles.size() / 3);
  m.blendshapes = blendshapes.data();
  m.blendshape_count = 52;
  return m;
}

AvatarFile assemble_avatar(SourceScene scene, const std::string& path, const ShapeNames& names, const ImportLimits& limits) {
  AvatarFile avatar;
  avatar.path = path;
  avatar.format = scene.format;
  avatar.declared_unit = scene.declared_unit;
  avatar.declared_metres_per_unit = scene.declared_metres_per_unit;
  avatar.vertex_order = scene.vertex_order;
  avatar.names_file = names.file();

  std::vector<std::pair<const SourceMesh*, ShapeChoice>> included;
  std::size_t total = 0;
  for (const SourceMesh& mesh : scene.meshes) {
    std::vector<std::string> shape_names;
    for (const SourceShape& s : mesh.shapes) shape_names.push_back(s.name);
    ShapeChoice choice = choose_shapes(shape_names, names);
    std::string reason;
    if (choice.count() == 0) reason = mesh.shapes.empty() ? "no blendshapes" : "no ARKit shape among its blendshapes";
    else if (mesh.triangles.empty()) reason = "no triangles";
    for (const UnusedShape& u : choice.unused) avatar.names_not_used.push_back({mesh.name, mesh.shapes[u.shape].name, u.reason});
    if (!reason.empty()) {
      avatar.left_out.push_back({mesh.name, reason, mesh.vertex_count()});
      continue;
    }
    check_mesh(path, mesh, choice);
    total += mesh.vertex_count();
    if (total > limits.max_vertices)
      throw std::runtime_error(path + ": the meshes with ARKit shapes have more than the " + std::to_string(limits.max_vertices) +
                               " vertices an avatar may have");
    included.emplace_back(&mesh, std::move(choice));
  }
  if (included.empty()) {
    std::string meshes;
    for (const LeftOutMesh& m : avatar.left_out) meshes += (meshes.empty() ? "" : ", ") + ("'" + m.name + "' (" + m.reason + ")");
    throw std::runtime_error(path + ": no mesh carries an ARKit blendshape" + (meshes.empty() ? " (no meshes)" : ": " + meshes) +
                             "; name the shapes as ARKit does (eyeBlinkLeft, jawOpen, ...) or map them with --names FILE");
  }

  avatar.neutral.resize(3 * total);
  avatar.blendshapes.assign(52 * 3 * total, 0.0f);
  std::map<std::string, int> seen;
  std::size_t first = 0;
  for (const auto& [mesh, choice] : included) {
    AvatarPart part = append(avatar, *mesh, choice, first, total);
    part.name = unique_name(mesh->name, seen);
    for (std::size_t k = 0; k < 52; ++k)
      if (choice.chosen[k] >= 0) avatar.shape_sources[k].push_back({part.name, mesh->shapes[static_cast<std::size_t>(choice.chosen[k])].name});
    first += part.vertex_count;
    avatar.parts.push_back(std::move(part));
  }
  return avatar;
}

AvatarFile read_avatar_file(const std::string& path, const ShapeNames& names, const ImportLimits& limits) {
  if (is_directory(path)) return assemble_avatar(read_avatar_folder(path, names, limits), path, names, limits);
  if (!is_avatar_file_name(path))
    throw std::runtime_error(path + ": not an avatar (a .gltf, .glb, .vrm or .fbx file, or a folder with neutral.obj)");
  return assemble_avatar(read_scene_file(path, limits), path, names, limits);
}

std::string avatar_mesh_sha256(const AvatarFile& avatar) {
  const auto digest = [](const auto& values) {
    return runtime::sha256_hex(reinterpret_cast<const std::uint8_t*>(values.data()), values.size() * sizeof(values[0]));
  };
  const std::string all = digest(avatar.neutral) + digest(avatar.triangles) + digest(avatar.blendshapes);
  return runtime::sha256_hex(reinterpret_cast<const std::uint8_t*>(all.data()), all.size());
}

}  // namespace softdeca::avatar_import
