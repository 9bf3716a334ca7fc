// Users' avatars for the avatar file tests, written as DCC tools write them: binary glTF with
// morph targets named in mesh.extras.targetNames (Blender, VRM), and binary FBX 7.4 with
// BlendShape deformers, channels and Shape geometries (Maya, Blender), including in-between
// shapes. Written here rather than by assimp's exporters: the Debian assimp (5.2) drops glTF
// target names, writes no FBX blend shapes, and its binary FBX does not read back.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "softdeca/softdeca.h"

namespace softdeca::test {

// The canonical index of an ARKit shape by its name (the C ABI's rule).
inline std::size_t arkit_index(const char* name) {
  int32_t index = -1;
  EXPECT_EQ(softdeca_blendshape_index(name, &index), SOFTDECA_OK);
  EXPECT_GE(index, 0) << name;
  return static_cast<std::size_t>(index);
}

// Deltas that differ per vertex and per shape, so a reordering or a mix-up shows: scale x
// (1 + vertex + 10 x coordinate), zero before vertex `only_from`.
inline std::vector<float> deltas(std::size_t vertices, float scale, std::size_t only_from = 0) {
  std::vector<float> d(3 * vertices, 0.0f);
  for (std::size_t i = only_from; i < vertices; ++i)
    for (std::size_t c = 0; c < 3; ++c) d[3 * i + c] = scale * static_cast<float>(1 + i + 10 * c);
  return d;
}

struct TestShape {
  std::string name;
  std::vector<float> deltas;     // vertex_count x 3
  std::vector<float> inbetween;  // FBX only: an in-between at 50 % (written before the full shape), or empty
};

struct TestMesh {
  std::string name;
  std::vector<float> vertices;
  std::vector<std::int32_t> triangles;
  std::vector<TestShape> shapes;
  double translation[3] = {0, 0, 0};
  double rotation_y_degrees = 0;
  double scale[3] = {1, 1, 1};
};

// Meshes under one root node ("Armature") that scales them all.
struct TestScene {
  double root_scale = 1;
  double fbx_unit_cm = 1;  // FBX's UnitScaleFactor
  std::vector<TestMesh> meshes;
};

// A folder in the test's temporary directory, removed at the end.
struct TempDir {
  std::filesystem::path dir;
  explicit TempDir(const std::string& tag) {
    dir = std::filesystem::temp_directory_path() / ("softdeca-" + tag + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  std::string file(const std::string& name) const { return (dir / name).string(); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::filesystem::create_directories((dir / name).parent_path());
    std::ofstream(file(name), std::ios::binary | std::ios::trunc) << bytes;
    return file(name);
  }
};

// The node transform the scene gives a mesh (root scale, then T R S), row-major 4x4.
inline std::vector<double> expected_transform(const TestScene& scene, const TestMesh& m) {
  const double a = m.rotation_y_degrees * M_PI / 180, c = std::cos(a), s = std::sin(a), k = scene.root_scale;
  const double r[3][3] = {{c, 0, s}, {0, 1, 0}, {-s, 0, c}};
  std::vector<double> t(16, 0.0);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) t[4 * i + j] = k * r[i][j] * m.scale[j];
    t[4 * i + 3] = k * m.translation[i];
  }
  t[15] = 1;
  return t;
}

namespace files_detail {
template <class T>
void append(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}
inline void append(std::string& out, const float* values, std::size_t count) {
  out.append(reinterpret_cast<const char*>(values), count * sizeof(float));
}
inline std::string numbers(const double* v, int n) {
  std::string out = "[";
  for (int i = 0; i < n; ++i) out += (i ? "," : "") + std::to_string(v[i]);
  return out + "]";
}
inline void pad(std::string& s, char with) {
  while (s.size() % 4) s += with;
}

// ---- binary FBX 7.4: nodes with typed properties ----
struct FbxProperty {
  char type;
  std::string bytes;
};
struct FbxNode {
  std::string name;
  std::vector<FbxProperty> properties;
  std::vector<FbxNode> children;
};
inline FbxProperty fbx_int(std::int32_t v) {
  std::string b;
  append(b, v);
  return {'I', b};
}
inline FbxProperty fbx_long(std::int64_t v) {
  std::string b;
  append(b, v);
  return {'L', b};
}
inline FbxProperty fbx_double(double v) {
  std::string b;
  append(b, v);
  return {'D', b};
}
inline FbxProperty fbx_string(const std::string& s) {
  std::string b;
  append(b, static_cast<std::uint32_t>(s.size()));
  return {'S', b + s};
}
// An object's name as FBX stores it: "name\0\1Class".
inline FbxProperty fbx_name(const std::string& name, const std::string& cls) { return fbx_string(name + std::string("\0\1", 2) + cls); }
template <class T>
FbxProperty fbx_array(char type, const std::vector<T>& v) {
  std::string b;
  append(b, static_cast<std::uint32_t>(v.size()));
  append(b, std::uint32_t{0});  // not compressed
  append(b, static_cast<std::uint32_t>(v.size() * sizeof(T)));
  b.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  return {type, b};
}
inline std::vector<double> to_doubles(const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); }

inline void fbx_put(std::string& out, const FbxNode& node) {
  const std::size_t start = out.size();
  out += std::string(13, '\0');
  out += node.name;
  std::string properties;
  for (const FbxProperty& p : node.properties) properties += p.type + p.bytes;
  out += properties;
  for (const FbxNode& child : node.children) fbx_put(out, child);
  if (!node.children.empty()) out += std::string(13, '\0');
  const auto end = static_cast<std::uint32_t>(out.size()), count = static_cast<std::uint32_t>(node.properties.size()),
             length = static_cast<std::uint32_t>(properties.size());
  const auto name_length = static_cast<std::uint8_t>(node.name.size());
  std::memcpy(&out[start], &end, 4);
  std::memcpy(&out[start + 4], &count, 4);
  std::memcpy(&out[start + 8], &length, 4);
  std::memcpy(&out[start + 12], &name_length, 1);
}
inline FbxNode fbx_p(const std::string& name, const std::string& type, const std::string& flags, const double* v) {
  return {"P", {fbx_string(name), fbx_string(type), fbx_string(""), fbx_string(flags), fbx_double(v[0]), fbx_double(v[1]), fbx_double(v[2])}, {}};
}
inline FbxNode fbx_model(std::int64_t id, const std::string& name, const std::string& cls, const double* t, const double* r, const double* s) {
  return {"Model",
          {fbx_long(id), fbx_name(name, "Model"), fbx_string(cls)},
          {{"Version", {fbx_int(232)}, {}},
           {"Properties70", {}, {fbx_p("Lcl Translation", "Lcl Translation", "A", t), fbx_p("Lcl Rotation", "Lcl Rotation", "A", r),
                                 fbx_p("Lcl Scaling", "Lcl Scaling", "A", s)}}}};
}
// A Shape geometry of the vertices a shape moves (as DCCs write them: sparse).
inline FbxNode fbx_shape(std::int64_t id, const std::string& name, const std::vector<float>& deltas) {
  std::vector<std::int32_t> indexes;
  std::vector<double> moved;
  for (std::size_t i = 0; i < deltas.size() / 3; ++i) {
    if (deltas[3 * i] == 0 && deltas[3 * i + 1] == 0 && deltas[3 * i + 2] == 0) continue;
    indexes.push_back(static_cast<std::int32_t>(i));
    moved.insert(moved.end(), {deltas[3 * i], deltas[3 * i + 1], deltas[3 * i + 2]});
  }
  return {"Geometry",
          {fbx_long(id), fbx_name(name, "Geometry"), fbx_string("Shape")},
          {{"Version", {fbx_int(100)}, {}},
           {"Indexes", {fbx_array('i', indexes)}, {}},
           {"Vertices", {fbx_array('d', moved)}, {}},
           {"Normals", {fbx_array('d', std::vector<double>(moved.size(), 0.0))}, {}}}};
}
}  // namespace files_detail

// Binary glTF 2.0: a node per mesh under the root node, morph targets named in extras.
inline std::string glb_bytes(const TestScene& scene) {
  using namespace files_detail;
  std::string bin, views, accessors, meshes, nodes;
  int accessor = 0;
  const auto add_view = [&](const std::string& bytes, int component, std::size_t count, const char* type) {
    const int view = accessor;
    views += std::string(view ? "," : "") + "{\"buffer\":0,\"byteOffset\":" + std::to_string(bin.size()) +
             ",\"byteLength\":" + std::to_string(bytes.size()) + "}";
    accessors += std::string(view ? "," : "") + "{\"bufferView\":" + std::to_string(view) + ",\"componentType\":" +
                 std::to_string(component) + ",\"count\":" + std::to_string(count) + ",\"type\":\"" + type + "\"}";
    bin += bytes;
    pad(bin, '\0');
    return accessor++;
  };
  std::string children;
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    const TestMesh& mesh = scene.meshes[m];
    std::string positions, indices;
    append(positions, mesh.vertices.data(), mesh.vertices.size());
    for (const std::int32_t i : mesh.triangles) append(indices, static_cast<std::uint32_t>(i));
    const int pos = add_view(positions, 5126, mesh.vertices.size() / 3, "VEC3");
    const int idx = add_view(indices, 5125, mesh.triangles.size(), "SCALAR");
    std::string targets, names;
    for (std::size_t s = 0; s < mesh.shapes.size(); ++s) {
      std::string deltas;
      append(deltas, mesh.shapes[s].deltas.data(), mesh.shapes[s].deltas.size());
      const int t = add_view(deltas, 5126, mesh.shapes[s].deltas.size() / 3, "VEC3");
      targets += std::string(s ? "," : "") + "{\"POSITION\":" + std::to_string(t) + "}";
      names += std::string(s ? "," : "") + "\"" + mesh.shapes[s].name + "\"";
    }
    meshes += std::string(m ? "," : "") + "{\"name\":\"" + mesh.name + "\",\"primitives\":[{\"attributes\":{\"POSITION\":" +
              std::to_string(pos) + "},\"indices\":" + std::to_string(idx) + ",\"mode\":4" +
              (targets.empty() ? "" : ",\"targets\":[" + targets + "]") + "}]" +
              (names.empty() ? "" : ",\"extras\":{\"targetNames\":[" + names + "]}") + "}";
    const double half = mesh.rotation_y_degrees * M_PI / 360;
    const double rotation[4] = {0, std::sin(half), 0, std::cos(half)};
    nodes += ",{\"name\":\"" + mesh.name + "\",\"mesh\":" + std::to_string(m) + ",\"translation\":" + numbers(mesh.translation, 3) +
             ",\"rotation\":" + numbers(rotation, 4) + ",\"scale\":" + numbers(mesh.scale, 3) + "}";
    children += std::string(m ? "," : "") + std::to_string(m + 1);
  }
  const double root[3] = {scene.root_scale, scene.root_scale, scene.root_scale};
  std::string json = "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"name\":\"Armature\",\"scale\":" +
                     numbers(root, 3) + ",\"children\":[" + children + "]}" + nodes + "],\"meshes\":[" + meshes +
                     "],\"buffers\":[{\"byteLength\":" + std::to_string(bin.size()) + "}],\"bufferViews\":[" + views +
                     "],\"accessors\":[" + accessors + "]}";
  pad(json, ' ');
  std::string glb = "glTF";
  append(glb, std::uint32_t{2});
  append(glb, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  append(glb, static_cast<std::uint32_t>(json.size()));
  glb += "JSON" + json;
  append(glb, static_cast<std::uint32_t>(bin.size()));
  glb += std::string("BIN\0", 4) + bin;
  return glb;
}

// Binary FBX 7.4: a Model, a Mesh geometry and a BlendShape deformer per mesh, under a Null
// model for the root; the file's unit is UnitScaleFactor centimetres.
inline std::string fbx_bytes(const TestScene& scene) {
  using namespace files_detail;
  std::vector<FbxNode> top;
  top.push_back({"FBXHeaderExtension", {}, {{"FBXHeaderVersion", {fbx_int(1003)}, {}}, {"FBXVersion", {fbx_int(7400)}, {}}}});
  top.push_back({"GlobalSettings",
                 {},
                 {{"Version", {fbx_int(1000)}, {}},
                  {"Properties70",
                   {},
                   {{"P", {fbx_string("UpAxis"), fbx_string("int"), fbx_string("Integer"), fbx_string(""), fbx_int(1)}, {}},
                    {"P", {fbx_string("UnitScaleFactor"), fbx_string("double"), fbx_string("Number"), fbx_string(""), fbx_double(scene.fbx_unit_cm)}, {}}}}}});
  FbxNode objects{"Objects", {}, {}}, connections{"Connections", {}, {}};
  const auto connect = [&](std::int64_t child, std::int64_t parent) {
    connections.children.push_back({"C", {fbx_string("OO"), fbx_long(child), fbx_long(parent)}, {}});
  };
  const double zero[3] = {0, 0, 0}, root_scale[3] = {scene.root_scale, scene.root_scale, scene.root_scale};
  objects.children.push_back(fbx_model(1000, "Armature", "Null", zero, zero, root_scale));
  connect(1000, 0);
  std::int64_t id = 2000;
  for (const TestMesh& mesh : scene.meshes) {
    const std::int64_t model = id++, geometry = id++;
    std::vector<std::int32_t> polygons(mesh.triangles.begin(), mesh.triangles.end());
    for (std::size_t t = 2; t < polygons.size(); t += 3) polygons[t] = ~polygons[t];  // a polygon's last corner, negated
    objects.children.push_back({"Geometry",
                                {fbx_long(geometry), fbx_name(mesh.name, "Geometry"), fbx_string("Mesh")},
                                {{"Vertices", {fbx_array('d', to_doubles(mesh.vertices))}, {}},
                                 {"PolygonVertexIndex", {fbx_array('i', polygons)}, {}},
                                 {"GeometryVersion", {fbx_int(124)}, {}}}});
    const double rotation[3] = {0, mesh.rotation_y_degrees, 0};
    objects.children.push_back(fbx_model(model, mesh.name, "Mesh", mesh.translation, rotation, mesh.scale));
    connect(model, 1000);
    connect(geometry, model);
    if (mesh.shapes.empty()) continue;
    const std::int64_t deformer = id++;
    objects.children.push_back({"Deformer", {fbx_long(deformer), fbx_name(mesh.name, "Deformer"), fbx_string("BlendShape")}, {{"Version", {fbx_int(100)}, {}}}});
    connect(deformer, geometry);
    for (const TestShape& shape : mesh.shapes) {
      const std::int64_t channel = id++;
      const std::vector<double> weights = shape.inbetween.empty() ? std::vector<double>{100} : std::vector<double>{50, 100};
      objects.children.push_back({"Deformer",
                                  {fbx_long(channel), fbx_name(shape.name, "SubDeformer"), fbx_string("BlendShapeChannel")},
                                  {{"Version", {fbx_int(100)}, {}}, {"DeformPercent", {fbx_double(0)}, {}}, {"FullWeights", {fbx_array('d', weights)}, {}}}});
      connect(channel, deformer);
      if (!shape.inbetween.empty()) {
        objects.children.push_back(fbx_shape(id, shape.name + "_50", shape.inbetween));
        connect(id++, channel);
      }
      objects.children.push_back(fbx_shape(id, shape.name, shape.deltas));
      connect(id++, channel);
    }
  }
  top.push_back(objects);
  top.push_back(connections);
  std::string out("Kaydara FBX Binary  \0\x1a\0", 23);
  append(out, std::uint32_t{7400});
  for (const FbxNode& node : top) fbx_put(out, node);
  return out + std::string(13, '\0');
}

}  // namespace softdeca::test
