#include "avatar_file.h"

#include <sys/stat.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "bundle/sha256.h"
#include "file_format.h"
#include "fit/value_bounds.h"

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

// The checks of one included mesh before anything is copied.
void check_mesh(const std::string& path, const SourceMesh& mesh, const ShapeChoice& choice) {
  const std::string at = where(path, mesh);
  require_finite(mesh.vertices, at);
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
  }
  for (const double v : mesh.transform)
    if (!std::isfinite(v)) throw std::runtime_error(at + "its node's transform is not finite");
  const double det = Eigen::Map<const Matrix>(mesh.transform).topLeftCorner<3, 3>().determinant();
  if (!(std::abs(det) > 1e-30)) throw std::runtime_error(at + "its node's transform is singular (a zero scale)");
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", x);
  return text;
}

std::string point(const Eigen::Vector3d& x) { return "(" + number(x[0]) + ", " + number(x[1]) + ", " + number(x[2]) + ")"; }

// The values the avatar's own size bounds (fit/value_bounds.h), checked once the parts are in
// their common space: a stray vertex, a shape's delta beyond the avatar's size. The error
// names the part, its own vertex and the shape by the rig's name.
void check_values(const AvatarFile& avatar) {
  const std::size_t n = avatar.vertex_count();
  const fit::MeshExtent extent = fit::mesh_extent(avatar.neutral.data(), n);
  const auto part_of = [&](std::size_t v) -> const AvatarPart& {
    for (const AvatarPart& p : avatar.parts)
      if (v >= p.first_vertex && v < p.first_vertex + p.vertex_count) return p;
    return avatar.parts.back();
  };
  const auto at = [&](std::size_t v) {
    const AvatarPart& p = part_of(v);
    return avatar.path + ": mesh '" + p.name + "': ";
  };
  const auto own = [&](std::size_t v) { return std::to_string(v - part_of(v).first_vertex); };
  const std::int64_t stray = fit::stray_vertex(avatar.neutral.data(), n, extent);
  if (stray >= 0) {
    const auto v = static_cast<std::size_t>(stray);
    throw std::runtime_error(at(v) + "vertex " + own(v) + " lies at " + point(Eigen::Vector3f(&avatar.neutral[3 * v]).cast<double>()) +
                             ", far outside the mesh: its vertices lie within " + point(extent.lo) + " to " + point(extent.hi) +
                             " (a stray vertex?)");
  }
  for (std::size_t k = 0; k < 52; ++k) {
    const std::int64_t moved = fit::long_delta(avatar.blendshapes.data() + 3 * k * n, n, extent);
    if (moved < 0) continue;
    const auto v = static_cast<std::size_t>(moved);
    std::string rig_name;
    for (const ShapeSource& s : avatar.shape_sources[k])
      if (s.part == part_of(v).name) rig_name = s.rig_name;
    throw std::runtime_error(at(v) + "shape '" + rig_name + "' moves vertex " + own(v) + " by " +
                             number(Eigen::Vector3f(&avatar.blendshapes[3 * (k * n + v)]).cast<double>().norm()) +
                             ", more than " + number(fit::kMaxDeltaReach) + " times the avatar's size (" + number(extent.diagonal()) + ")");
  }
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
  check_values(avatar);
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
    return bundle::sha256_hex(reinterpret_cast<const std::uint8_t*>(values.data()), values.size() * sizeof(values[0]));
  };
  const std::string all = digest(avatar.neutral) + digest(avatar.triangles) + digest(avatar.blendshapes);
  return bundle::sha256_hex(reinterpret_cast<const std::uint8_t*>(all.data()), all.size());
}

}  // namespace softdeca::avatar_import
