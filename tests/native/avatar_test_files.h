// Users' avatars for the avatar file tests, written as DCC tools write them: binary glTF with
// morph targets named in mesh.extras.targetNames (Blender, VRM), and binary FBX 7.4 with
// BlendShape deformers, channels and Shape geometries (Maya, Blender), including in-between
// shapes, its arrays raw or zlib-compressed. Written here rather than by assimp's exporters:
// the Debian assimp (5.2) drops glTF target names, writes no FBX blend shapes, and its binary
// FBX does not read back. Hostile FBX too: nodes nested deep, arrays that expand far.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "avatar_file.h"
#include "softdeca/softdeca.h"

namespace softdeca::test {

// What reading the avatar at `path` is refused with, "" when it reads.
inline std::string error_of(const std::string& path, const avatar_import::ImportLimits& limits = {}) {
  try {
    avatar_import::read_avatar_file(path, avatar_import::ShapeNames(), limits);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// The canonical index of an ARKit shape by its name (the C ABI's rule).
inline std::size_t arkit_index(const char* name) {
  int32_t index = -1;
  EXPECT_EQ(softdeca_blendshape_find_index(name, &index), SOFTDECA_OK);
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
  bool fbx_zlib = false;   // FBX arrays zlib-compressed (as DCCs write large ones)
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

// ---- zlib streams (RFC 1950) of fixed-Huffman deflate blocks (RFC 1951), written by hand ----
struct BitWriter {
  std::string out;
  std::uint32_t held = 0;
  int count = 0;
  void bits(std::uint32_t value, int n) {  // the deflate stream's own order: least significant first
    for (int i = 0; i < n; ++i) put((value >> i) & 1u);
  }
  void code(std::uint32_t value, int n) {  // Huffman codes: most significant first
    for (int i = n - 1; i >= 0; --i) put((value >> i) & 1u);
  }
  void put(std::uint32_t bit) {
    held |= bit << count;
    if (++count == 8) out += static_cast<char>(held), held = 0, count = 0;
  }
  void align() {
    while (count) put(0);
  }
};
inline void deflate_literal(BitWriter& w, unsigned char v) {
  if (v < 144) w.code(0x30u + v, 8);
  else w.code(0x190u + (v - 144u), 9);
}
inline void deflate_zero_run(BitWriter& w) {  // 258 bytes copied from one back: length code 285, distance code 0
  w.code(0xC5, 8);
  w.code(0, 5);
}
inline std::string zlib_finish(BitWriter& w, std::uint32_t adler) {
  w.code(0, 7);  // end of block
  w.align();
  for (int shift = 24; shift >= 0; shift -= 8) w.out += static_cast<char>((adler >> shift) & 0xFF);
  return std::string("\x78\x01", 2) + w.out;
}
// `bytes` as a zlib stream: runs of zeros as copies, everything else as literals.
inline std::string zlib_stream(const std::string& bytes) {
  BitWriter w;
  w.bits(1, 1);  // the final block
  w.bits(1, 2);  // fixed Huffman codes
  std::uint32_t a = 1, b = 0;
  for (std::size_t i = 0; i < bytes.size();) {
    const auto run = [&] {
      std::size_t n = 0;
      while (n < 258 && i + n < bytes.size() && bytes[i + n] == 0) ++n;
      return n;
    };
    if (i > 0 && bytes[i - 1] == 0 && run() == 258) {
      deflate_zero_run(w);
      for (int k = 0; k < 258; ++k) b = (b + a) % 65521;
      i += 258;
      continue;
    }
    const auto v = static_cast<unsigned char>(bytes[i++]);
    deflate_literal(w, v);
    a = (a + v) % 65521;
    b = (b + a) % 65521;
  }
  return zlib_finish(w, (b << 16) | a);
}
// `n` zero bytes (n >= 1) as a zlib stream of about 13 bits per 258 of them: a zlib bomb.
inline std::string zlib_zeros(std::uint64_t n) {
  BitWriter w;
  w.bits(1, 1);
  w.bits(1, 2);
  deflate_literal(w, 0);
  std::uint64_t left = n - 1;
  for (; left >= 258; left -= 258) deflate_zero_run(w);
  for (; left > 0; --left) deflate_literal(w, 0);
  return zlib_finish(w, static_cast<std::uint32_t>((n % 65521) << 16 | 1));  // Adler-32 of zeros: A = 1, B = n
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
// An array property: raw, or zlib-compressed (encoding 1).
template <class T>
FbxProperty fbx_array(char type, const std::vector<T>& v, bool zlib = false) {
  std::string data(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  if (zlib) data = zlib_stream(data);
  std::string b;
  append(b, static_cast<std::uint32_t>(v.size()));
  append(b, std::uint32_t{zlib ? 1u : 0u});
  append(b, static_cast<std::uint32_t>(data.size()));
  return {type, b + data};
}
// An array property of `count` elements of `element_size` bytes, declared so, holding `data`
// under `encoding` whatever its size: for hostile files.
inline FbxProperty fbx_array_declared(char type, std::uint32_t count, std::uint32_t encoding, const std::string& data) {
  std::string b;
  append(b, count);
  append(b, encoding);
  append(b, static_cast<std::uint32_t>(data.size()));
  return {type, b + data};
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
inline FbxNode fbx_shape(std::int64_t id, const std::string& name, const std::vector<float>& deltas, bool zlib) {
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
           {"Indexes", {fbx_array('i', indexes, zlib)}, {}},
           {"Vertices", {fbx_array('d', moved, zlib)}, {}},
           {"Normals", {fbx_array('d', std::vector<double>(moved.size(), 0.0), zlib)}, {}}}};
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
// model for the root; the file's unit is UnitScaleFactor centimetres. `edit` and `edit_links`
// (a test's) may change the Objects and the Connections node before they are written.
inline std::string fbx_bytes(const TestScene& scene, const std::function<void(files_detail::FbxNode& objects)>& edit = {},
                             const std::function<void(files_detail::FbxNode& connections)>& edit_links = {}) {
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
                                {{"Vertices", {fbx_array('d', to_doubles(mesh.vertices), scene.fbx_zlib)}, {}},
                                 {"PolygonVertexIndex", {fbx_array('i', polygons, scene.fbx_zlib)}, {}},
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
                                  {{"Version", {fbx_int(100)}, {}}, {"DeformPercent", {fbx_double(0)}, {}}, {"FullWeights", {fbx_array('d', weights, scene.fbx_zlib)}, {}}}});
      connect(channel, deformer);
      if (!shape.inbetween.empty()) {
        objects.children.push_back(fbx_shape(id, shape.name + "_50", shape.inbetween, scene.fbx_zlib));
        connect(id++, channel);
      }
      objects.children.push_back(fbx_shape(id, shape.name, shape.deltas, scene.fbx_zlib));
      connect(id++, channel);
    }
  }
  if (edit) edit(objects);
  if (edit_links) edit_links(connections);
  top.push_back(objects);
  top.push_back(connections);
  std::string out("Kaydara FBX Binary  \0\x1a\0", 23);
  append(out, std::uint32_t{7400});
  for (const FbxNode& node : top) fbx_put(out, node);
  return out + std::string(13, '\0');
}

// The first node named `name` among `node`'s descendants (depth first), or null.
inline files_detail::FbxNode* fbx_find(files_detail::FbxNode& node, const std::string& name) {
  for (files_detail::FbxNode& child : node.children) {
    if (child.name == name) return &child;
    if (files_detail::FbxNode* found = fbx_find(child, name)) return found;
  }
  return nullptr;
}

// A binary FBX 7.4 of nodes nested `depth` deep, each the only child of the one above (written
// without recursion: deep enough to overflow a recursive reader's stack).
inline std::string fbx_nested_bytes(std::size_t depth) {
  using files_detail::append;
  std::string out("Kaydara FBX Binary  \0\x1a\0", 23);
  append(out, std::uint32_t{7400});
  std::vector<std::size_t> starts;
  for (std::size_t d = 0; d < depth; ++d) {
    starts.push_back(out.size());
    out += std::string(12, '\0') + std::string(1, '\1') + "N";  // end, 0 properties, 0 bytes; a 1-byte name
  }
  std::vector<std::uint32_t> ends(depth);
  ends[depth - 1] = static_cast<std::uint32_t>(out.size());
  for (std::size_t d = depth - 1; d-- > 0;) {
    out += std::string(13, '\0');  // the empty record that ends a node's children
    ends[d] = static_cast<std::uint32_t>(out.size());
  }
  for (std::size_t d = 0; d < depth; ++d) std::memcpy(&out[starts[d]], &ends[d], 4);
  return out + std::string(13, '\0');
}

// An ASCII FBX whose header is followed by `depth` nested braces.
inline std::string fbx_ascii_nested(std::size_t depth) {
  std::string out = "; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n}\nDeep: ";
  for (std::size_t d = 0; d < depth; ++d) out += "A: {";
  return out + std::string(depth, '}') + "\n";
}

}  // namespace softdeca::test
