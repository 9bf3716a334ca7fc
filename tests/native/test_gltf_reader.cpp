// The glTF 2.0 reader (plugin/import/gltf_reader.h): one avatar written in every encoding a
// glTF may use for its meshes (plain, buffer-less and sparse morph targets, KHR_mesh_quantization,
// EXT_meshopt_compression, KHR_draco_mesh_compression, several primitives, each place target
// names are kept, VRM 0.x and 1.0 expressions, gltfpack's output) reads as the plain file does,
// within the encoding's quantisation step; hostile files get errors that say what is wrong, fast.
// Kept whole: every encoding is compared with the same plain file, all written by this file's
// writer; the hostile cases edit that file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "avatar_test_files.h"
#include "gltf_draco.h"
#include "gltf_draco_header.h"
#include "gltf_meshopt.h"
#include "gltf_reader.h"

#if SOFTDECA_TEST_MESHOPT
#include <meshoptimizer.h>
#endif
#if SOFTDECA_TEST_DRACO
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <draco/metadata/geometry_metadata.h>
#endif

using softdeca::avatar_import::ImportLimits;
using softdeca::avatar_import::read_gltf;
using softdeca::avatar_import::SourceMesh;
using softdeca::avatar_import::SourceScene;
using softdeca::avatar_import::SourceShape;
using softdeca::test::deltas;
using softdeca::test::TempDir;
using softdeca::test::TestMesh;
using softdeca::test::TestScene;

namespace {
// ---- the avatar ----------------------------------------------------------------------------

// A head of two parts (an octahedron, vertices 0-5, and a tetrahedron, 6-9) and teeth, under a
// root node that scales them to metres; deltas up to half a unit (deltas() grows to 30 times its
// scale over 10 vertices), so an 8-bit normalized delta holds them.
TestScene avatar() {
  TestMesh head;
  head.name = "Head";
  head.vertices = {0, 0, 1, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 0, 0, -1,  // octahedron
                   2, 0, 0, 3, 0, 0, 2, 1, 0, 2, 0, 1};                     // tetrahedron
  head.triangles = {4, 1, 0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 1, 4, 5, 2, 1, 5, 3, 2, 5, 4, 3, 5,  // octahedron
                    6, 7, 8, 7, 9, 8, 8, 9, 6, 9, 7, 6};                                     // tetrahedron (a strip's order)
  head.shapes = {{"eyeBlinkLeft", deltas(10, 0.5f / 30), {}}, {"jawOpen", deltas(10, -0.25f / 30, 4), {}},
                 {"mouthSmileLeft", deltas(10, 0.125f / 30), {}}};
  head.translation[1] = 150;
  head.rotation_y_degrees = 90;
  TestMesh teeth;
  teeth.name = "Teeth";
  teeth.vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  teeth.triangles = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
  teeth.shapes = {{"jawOpen", deltas(4, -0.5f / 24), {}}};
  teeth.translation[1] = 145;
  teeth.scale[0] = teeth.scale[1] = teeth.scale[2] = 2;
  TestScene scene;
  scene.root_scale = 0.01;
  scene.meshes = {head, teeth};
  return scene;
}

// ---- writing glTF ----------------------------------------------------------------------------

template <class T>
std::string bytes_of(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

std::string number(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string numbers(const std::vector<double>& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? "," : "") + number(v[i]);
  return out + "]";
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? "," : "") + items[i];
  return out;
}

// The JSON parts and binary buffer 0 of a glTF under construction.
struct Gltf {
  std::string bin;
  std::vector<std::string> buffers_after_bin, views, accessors, meshes, nodes;
  std::string root_members;  // more members of the root object, each with a leading comma
  std::uint64_t fallback_length = 0;  // a second buffer without data, EXT_meshopt_compression's fallback

  void align() {
    while (bin.size() % 4) bin += '\0';
  }
  int view(const std::string& data, int stride = 0) {
    align();
    views.push_back("{\"buffer\":0,\"byteOffset\":" + std::to_string(bin.size()) + ",\"byteLength\":" + std::to_string(data.size()) +
                    (stride ? ",\"byteStride\":" + std::to_string(stride) : "") + "}");
    bin += data;
    return static_cast<int>(views.size()) - 1;
  }
  int accessor(const std::string& json) {
    accessors.push_back(json);
    return static_cast<int>(accessors.size()) - 1;
  }
  std::string json() const {
    std::vector<std::string> buffers = {"{\"byteLength\":" + std::to_string(std::max<std::size_t>(bin.size(), 4)) + "}"};
    if (fallback_length)
      buffers.push_back("{\"byteLength\":" + std::to_string(fallback_length) + ",\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}");
    for (const std::string& b : buffers_after_bin) buffers.push_back(b);
    return "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[" + join(nodes) + "],\"meshes\":[" +
           join(meshes) + "],\"buffers\":[" + join(buffers) + "],\"bufferViews\":[" + join(views) + "],\"accessors\":[" +
           join(accessors) + "]" + root_members + "}";
  }
  std::string glb() const { return glb_of(json(), bin); }

  static std::string glb_of(std::string json, std::string bin) {
    while (json.size() % 4) json += ' ';
    while (bin.size() % 4) bin += '\0';
    std::string out = "glTF";
    const auto put = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    put(2);
    put(static_cast<std::uint32_t>(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
    put(static_cast<std::uint32_t>(json.size()));
    out += "JSON" + json;
    if (!bin.empty()) {
      put(static_cast<std::uint32_t>(bin.size()));
      out += std::string("BIN\0", 4) + bin;
    }
    return out;
  }
};

// The avatar's teeth as a primitive of `g` (its POSITION and indices accessors), `more` members added.
std::string teeth_primitive(Gltf& g, const std::string& more = "") {
  const TestMesh teeth = avatar().meshes[1];
  std::vector<std::uint32_t> triangles(teeth.triangles.begin(), teeth.triangles.end());
  const int pos = g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(teeth.vertices), 12)) +
                             ",\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}");
  const int idx = g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(triangles))) + ",\"componentType\":5125,\"count\":" +
                             std::to_string(triangles.size()) + ",\"type\":\"SCALAR\"}");
  return "{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "},\"indices\":" + std::to_string(idx) + more + "}";
}

// How the avatar is written.
struct Encoding {
  bool quantized_positions = false;  // KHR_mesh_quantization: normalized shorts, the scale in the node
  bool quantized_deltas = false;     // normalized bytes
  bool sparse = false;               // morph targets as sparse accessors
  std::uint32_t sparse_indices = 5125;
  std::uint32_t sparse_values = 5126;  // or 5120 / 5122 normalized
  bool sparse_over_view = false;       // a bufferView holds the even vertices, sparse values the odd
  std::string names = "mesh";          // where target names are: "mesh", "primitive", "target", "none"
  std::size_t split_head_at = 0;       // the head as two primitives, vertices [0, k) and [k, n)
  bool meshopt = false;                // every view compressed, the uncompressed buffer a placeholder
  bool exponential = false;            // float deltas through meshopt's exponential filter
  bool draco = false;                  // the primitives' positions and indices
  std::string root_members;
};

float max_abs(const std::vector<float>& v) {
  float m = 0;
  for (const float x : v) m = std::max(m, std::abs(x));
  return m;
}

template <class T>
std::vector<T> quantize(const std::vector<float>& v, float scale, float steps, std::size_t components, std::size_t padded) {
  std::vector<T> out;
  for (std::size_t i = 0; i < v.size() / components; ++i)
    for (std::size_t c = 0; c < padded; ++c)
      out.push_back(c < components ? static_cast<T>(std::lround(v[components * i + c] / scale * steps)) : T{0});
  return out;
}

std::string min_max(const std::vector<float>& v) {
  std::vector<double> lo(3, 1e30), hi(3, -1e30);
  for (std::size_t i = 0; i < v.size(); ++i) {
    lo[i % 3] = std::min<double>(lo[i % 3], v[i]);
    hi[i % 3] = std::max<double>(hi[i % 3], v[i]);
  }
  return ",\"min\":" + numbers(lo) + ",\"max\":" + numbers(hi);
}

// A primitive's slice of a mesh: vertices [first, last), the triangles among them.
struct Slice {
  std::vector<float> vertices;
  std::vector<std::uint32_t> triangles;
  std::vector<std::vector<float>> deltas;
};

Slice slice(const TestMesh& m, std::size_t first, std::size_t last) {
  Slice s;
  s.vertices.assign(m.vertices.begin() + 3 * first, m.vertices.begin() + 3 * last);
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    const auto a = static_cast<std::size_t>(m.triangles[t]);
    if (a < first || a >= last) continue;
    for (int k = 0; k < 3; ++k) s.triangles.push_back(static_cast<std::uint32_t>(m.triangles[t + k]) - static_cast<std::uint32_t>(first));
  }
  for (const auto& shape : m.shapes) s.deltas.emplace_back(shape.deltas.begin() + 3 * first, shape.deltas.begin() + 3 * last);
  return s;
}

#if SOFTDECA_TEST_MESHOPT
// Moves view `v`'s bytes to a meshopt-compressed copy in buffer 0; the view itself points into
// the fallback buffer, which has no data.
void compress_view(Gltf& g, int v, std::size_t count, std::size_t stride, bool indices, bool exponential) {
  // Find the view's bytes: the last bytes appended for it.
  const std::string& json = g.views[static_cast<std::size_t>(v)];
  const auto field = [&](const char* key) {
    const std::size_t at = json.find(key);
    return std::stoull(json.substr(at + std::strlen(key)));
  };
  const std::size_t offset = field("\"byteOffset\":"), length = field("\"byteLength\":");
  std::string raw = g.bin.substr(offset, length);
  if (exponential) {
    std::vector<float> values(raw.size() / 4);
    std::memcpy(values.data(), raw.data(), raw.size());
    std::string filtered(raw.size(), '\0');
    meshopt_encodeFilterExp(filtered.data(), count, stride, 20, values.data());
    raw = filtered;
  }
  std::vector<unsigned char> out;
  if (indices) {
    std::vector<unsigned int> idx(count);
    std::memcpy(idx.data(), raw.data(), raw.size());
    out.resize(meshopt_encodeIndexBufferBound(count, 1 + *std::max_element(idx.begin(), idx.end())));
    out.resize(meshopt_encodeIndexBuffer(out.data(), out.size(), idx.data(), count));
  } else {
    out.resize(meshopt_encodeVertexBufferBound(count, stride));
    out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), raw.data(), count, stride));
  }
  g.align();
  const std::size_t compressed_at = g.bin.size();
  g.bin.append(reinterpret_cast<const char*>(out.data()), out.size());
  g.fallback_length = (g.fallback_length + 3) / 4 * 4;
  const std::size_t fallback_at = g.fallback_length;
  g.fallback_length += length;
  g.views[static_cast<std::size_t>(v)] =
      "{\"buffer\":1,\"byteOffset\":" + std::to_string(fallback_at) + ",\"byteLength\":" + std::to_string(length) +
      (indices ? "" : ",\"byteStride\":" + std::to_string(stride)) + ",\"extensions\":{\"EXT_meshopt_compression\":{\"buffer\":0,\"byteOffset\":" +
      std::to_string(compressed_at) + ",\"byteLength\":" + std::to_string(out.size()) + ",\"byteStride\":" + std::to_string(stride) +
      ",\"count\":" + std::to_string(count) + ",\"mode\":\"" + (indices ? "TRIANGLES" : "ATTRIBUTES") + "\"" +
      (exponential ? ",\"filter\":\"EXPONENTIAL\"" : "") + "}}}";
}
#endif

#if SOFTDECA_TEST_DRACO
// A Draco mesh of the positions and triangles, sequentially encoded (it keeps the point order,
// which the morph targets beside it rely on); its POSITION's unique id is 0.
std::string draco_bytes(const std::vector<float>& positions, const std::vector<std::uint32_t>& triangles) {
  draco::Mesh mesh;
  const std::size_t n = positions.size() / 3;
  mesh.set_num_points(static_cast<std::uint32_t>(n));
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, 12, 0);
  const int id = mesh.AddAttribute(position, true, static_cast<std::uint32_t>(n));
  for (std::size_t i = 0; i < n; ++i) mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(static_cast<std::uint32_t>(i)), &positions[3 * i]);
  for (std::size_t t = 0; t < triangles.size(); t += 3)
    mesh.AddFace({draco::PointIndex(triangles[t]), draco::PointIndex(triangles[t + 1]), draco::PointIndex(triangles[t + 2])});
  draco::Encoder encoder;
  encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  draco::EncoderBuffer buffer;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(mesh, &buffer).ok());
  return std::string(buffer.data(), buffer.size());
}
#endif

// A VEC3 accessor of `count` elements (`view` < 0: none), its bounds those of `values`.
int vec3_accessor(Gltf& g, int view, const std::string& component, std::size_t count, const std::vector<float>& values,
                  const std::string& more = "") {
  return g.accessor("{" + (view >= 0 ? "\"bufferView\":" + std::to_string(view) + "," : std::string()) + "\"componentType\":" + component +
                    ",\"count\":" + std::to_string(count) + ",\"type\":\"VEC3\"" + min_max(values) + more + "}");
}

int index_accessor(Gltf& g, int view, std::size_t count) {
  return g.accessor("{" + (view >= 0 ? "\"bufferView\":" + std::to_string(view) + "," : std::string()) +
                    "\"componentType\":5125,\"count\":" + std::to_string(count) + ",\"type\":\"SCALAR\"}");
}

// Morph target deltas (`local`, the mesh's own units) as a sparse accessor: the vertices they
// move, or with `sparse_over_view` a view of the even vertices and sparse values for the odd.
int sparse_target(Gltf& g, const std::vector<float>& local, const Encoding& e) {
  const std::size_t n = local.size() / 3;
  std::vector<std::uint32_t> moved;
  for (std::size_t i = 0; i < n; ++i)
    if ((local[3 * i] != 0 || local[3 * i + 1] != 0 || local[3 * i + 2] != 0) && (!e.sparse_over_view || i % 2 == 1))
      moved.push_back(static_cast<std::uint32_t>(i));
  int base = -1;
  if (e.sparse_over_view) {
    std::vector<float> even = local;
    for (std::size_t i = 1; i < n; i += 2) even[3 * i] = even[3 * i + 1] = even[3 * i + 2] = 0;
    base = g.view(bytes_of(even), 12);
  }
  if (moved.empty()) return vec3_accessor(g, base, "5126", n, local);
  std::string indices;
  std::vector<float> picked;
  for (const std::uint32_t i : moved) {
    picked.insert(picked.end(), {local[3 * i], local[3 * i + 1], local[3 * i + 2]});
    if (e.sparse_indices == 5121) indices += static_cast<char>(i);
    if (e.sparse_indices == 5123) indices += bytes_of(std::vector<std::uint16_t>{static_cast<std::uint16_t>(i)});
    if (e.sparse_indices == 5125) indices += bytes_of(std::vector<std::uint32_t>{i});
  }
  std::string values = bytes_of(picked), component = "5126";
  if (e.sparse_values == 5120) values = bytes_of(quantize<std::int8_t>(picked, 1, 127, 3, 3)), component = "5120,\"normalized\":true";
  if (e.sparse_values == 5122) values = bytes_of(quantize<std::int16_t>(picked, 1, 32767, 3, 3)), component = "5122,\"normalized\":true";
  const int iv = g.view(indices), vv = g.view(values);
  return vec3_accessor(g, base, component, n, local,
                       ",\"sparse\":{\"count\":" + std::to_string(moved.size()) + ",\"indices\":{\"bufferView\":" + std::to_string(iv) +
                           ",\"componentType\":" + std::to_string(e.sparse_indices) + "},\"values\":{\"bufferView\":" + std::to_string(vv) + "}}");
}

// Morph target deltas in a view of their own: floats, or normalized bytes (KHR_mesh_quantization).
int dense_target(Gltf& g, const std::vector<float>& local, const Encoding& e) {
  const std::size_t n = local.size() / 3;
  const std::size_t stride = e.quantized_deltas ? 4 : 12;
  const int view = e.quantized_deltas ? g.view(bytes_of(quantize<std::int8_t>(local, 1, 127, 3, 4)), 4) : g.view(bytes_of(local), 12);
#if SOFTDECA_TEST_MESHOPT
  if (e.meshopt) compress_view(g, view, n, stride, false, e.exponential && !e.quantized_deltas);
#else
  (void)stride;
#endif
  return vec3_accessor(g, view, e.quantized_deltas ? "5120,\"normalized\":true" : "5126", n, local);
}

// One primitive of `s` (positions divided by `q` where quantized), its accessors and views added
// to `g`; returns the primitive's JSON.
std::string write_primitive(Gltf& g, const Slice& s, const Encoding& e, float q, const std::vector<std::string>& names) {
  const std::size_t n = s.vertices.size() / 3;
  int position = -1, indices = -1;
  std::string draco;
  if (e.draco) {
#if SOFTDECA_TEST_DRACO
    const int view = g.view(draco_bytes(s.vertices, s.triangles));
    position = vec3_accessor(g, -1, "5126", n, s.vertices);
    indices = index_accessor(g, -1, s.triangles.size());
    draco = ",\"extensions\":{\"KHR_draco_mesh_compression\":{\"bufferView\":" + std::to_string(view) + ",\"attributes\":{\"POSITION\":0}}}";
#endif
  } else {
    std::vector<float> local = s.vertices;
    for (float& x : local) x /= q;
    const int pv = e.quantized_positions ? g.view(bytes_of(quantize<std::int16_t>(s.vertices, q, 32767, 3, 4)), 8)
                                         : g.view(bytes_of(s.vertices), 12);
    position = vec3_accessor(g, pv, e.quantized_positions ? "5122,\"normalized\":true" : "5126", n, local);
    const int iv = g.view(bytes_of(s.triangles));
    indices = index_accessor(g, iv, s.triangles.size());
#if SOFTDECA_TEST_MESHOPT
    if (e.meshopt) {
      compress_view(g, pv, n, e.quantized_positions ? 8 : 12, false, false);
      compress_view(g, iv, s.triangles.size(), 4, true, false);
    }
#endif
  }
  std::vector<std::string> targets;
  for (std::size_t t = 0; t < s.deltas.size(); ++t) {
    std::vector<float> local = s.deltas[t];
    for (float& x : local) x /= q;
    const int accessor = e.sparse ? sparse_target(g, local, e) : dense_target(g, local, e);
    targets.push_back("{\"POSITION\":" + std::to_string(accessor) +
                      (e.names == "target" ? ",\"extras\":{\"name\":\"" + names[t] + "\"}" : "") + "}");
  }
  std::string extras;
  if (e.names == "primitive") {
    std::vector<std::string> quoted;
    for (const std::string& name : names) quoted.push_back("\"" + name + "\"");
    extras = ",\"extras\":{\"targetNames\":[" + join(quoted) + "]}";
  }
  return "{\"attributes\":{\"POSITION\":" + std::to_string(position) + "},\"indices\":" + std::to_string(indices) + ",\"mode\":4" +
         (targets.empty() ? "" : ",\"targets\":[" + join(targets) + "]") + draco + extras + "}";
}

std::string write(const TestScene& scene, const Encoding& e) {
  Gltf g;
  g.root_members = e.root_members;
  std::vector<std::string> children;
  std::vector<std::string> used;
  if (e.quantized_positions || e.quantized_deltas) used.push_back("\"KHR_mesh_quantization\"");
  if (e.meshopt) used.push_back("\"EXT_meshopt_compression\"");
  if (e.draco) used.push_back("\"KHR_draco_mesh_compression\"");
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    const TestMesh& mesh = scene.meshes[m];
    const std::size_t n = mesh.vertices.size() / 3;
    float q = max_abs(mesh.vertices);
    for (const auto& s : mesh.shapes) q = std::max(q, max_abs(s.deltas));
    if (!e.quantized_positions) q = 1;
    std::vector<std::string> names;
    for (const auto& s : mesh.shapes) names.push_back(s.name);
    std::vector<std::string> primitives;
    const std::size_t split = m == 0 ? e.split_head_at : 0;
    if (split) {
      primitives.push_back(write_primitive(g, slice(mesh, 0, split), e, q, names));
      primitives.push_back(write_primitive(g, slice(mesh, split, n), e, q, names));
    } else {
      primitives.push_back(write_primitive(g, slice(mesh, 0, n), e, q, names));
    }
    std::string extras;
    if (e.names == "mesh" && !names.empty()) {
      std::vector<std::string> quoted;
      for (const std::string& name : names) quoted.push_back("\"" + name + "\"");
      extras = ",\"extras\":{\"targetNames\":[" + join(quoted) + "]}";
    }
    g.meshes.push_back("{\"name\":\"" + mesh.name + "\",\"primitives\":[" + join(primitives) + "]" + extras + "}");
    const double half = mesh.rotation_y_degrees * M_PI / 360;
    g.nodes.push_back("{\"name\":\"" + mesh.name + "\",\"mesh\":" + std::to_string(m) + ",\"translation\":" +
                      numbers({mesh.translation[0], mesh.translation[1], mesh.translation[2]}) + ",\"rotation\":" +
                      numbers({0, std::sin(half), 0, std::cos(half)}) + ",\"scale\":" +
                      numbers({mesh.scale[0] * q, mesh.scale[1] * q, mesh.scale[2] * q}) + "}");
    children.push_back(std::to_string(m + 1));
  }
  g.nodes.insert(g.nodes.begin(), "{\"name\":\"Armature\",\"scale\":" + numbers({scene.root_scale, scene.root_scale, scene.root_scale}) +
                                      ",\"children\":[" + join(children) + "]}");
  if (!used.empty()) g.root_members += ",\"extensionsUsed\":[" + join(used) + "]";
  return g.glb();
}

// ---- reading and comparing -------------------------------------------------------------------

std::string error_of(const std::string& path, const ImportLimits& limits = {}) {
  try {
    read_gltf(path, limits);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// Whether reading `path` fails with an error that contains `part`.
::testing::AssertionResult fails_with(const std::string& path, const std::string& part, const ImportLimits& limits = {}) {
  const std::string error = error_of(path, limits);
  if (!error.empty() && error.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "error '" << error << "' does not say '" << part << "'";
}

std::vector<double> placed(const SourceMesh& m, std::size_t i, const std::vector<float>& v, bool point) {
  std::vector<double> out(3);
  for (int r = 0; r < 3; ++r) {
    out[r] = point ? m.transform[4 * r + 3] : 0;
    for (int c = 0; c < 3; ++c) out[r] += m.transform[4 * r + c] * v[3 * i + static_cast<std::size_t>(c)];
  }
  return out;
}

const SourceShape* shape_named(const SourceMesh& m, const std::string& name) {
  for (const SourceShape& s : m.shapes)
    if (s.name == name) return &s;
  return nullptr;
}

// Each triangle turned to start at its smallest corner: the same triangles, the same way round
// (meshopt's index codec turns them so).
std::vector<std::int32_t> rotated(std::vector<std::int32_t> t) {
  for (std::size_t i = 0; i + 2 < t.size(); i += 3)
    while (t[i] > t[i + 1] || t[i] > t[i + 2]) std::rotate(t.begin() + static_cast<long>(i), t.begin() + static_cast<long>(i) + 1, t.begin() + static_cast<long>(i) + 3);
  return t;
}

// `got` is `want` in the scene's space: the same meshes, triangles, vertices and the named
// shapes' deltas within `tolerance` (metres).
void expect_same(const SourceScene& got, const SourceScene& want, double tolerance) {
  ASSERT_EQ(got.meshes.size(), want.meshes.size());
  for (std::size_t k = 0; k < want.meshes.size(); ++k) {
    const SourceMesh &g = got.meshes[k], &w = want.meshes[k];
    EXPECT_EQ(g.name, w.name);
    EXPECT_EQ(rotated(g.triangles), rotated(w.triangles)) << w.name;
    ASSERT_EQ(g.vertex_count(), w.vertex_count()) << w.name;
    for (std::size_t i = 0; i < w.vertex_count(); ++i) {
      const auto a = placed(g, i, g.vertices, true), b = placed(w, i, w.vertices, true);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tolerance) << w.name << " vertex " << i;
    }
    for (const SourceShape& ws : w.shapes) {
      const SourceShape* gs = shape_named(g, ws.name);
      ASSERT_NE(gs, nullptr) << w.name << " lacks shape " << ws.name;
      ASSERT_EQ(gs->deltas.size(), ws.deltas.size());
      for (std::size_t i = 0; i < w.vertex_count(); ++i) {
        const auto a = placed(g, i, gs->deltas, false), b = placed(w, i, ws.deltas, false);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tolerance) << w.name << " " << ws.name << " vertex " << i;
      }
    }
  }
}

class GltfReader : public ::testing::Test {
 protected:
  TempDir dir_{"gltf-reader"};
  SourceScene plain_;
  void SetUp() override { plain_ = read_gltf(dir_.write("plain.glb", write(avatar(), {})), {}); }
  SourceScene read(const std::string& name, const Encoding& e) { return read_gltf(dir_.write(name, write(avatar(), e)), {}); }
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

// ---- the same avatar in every encoding ------------------------------------------------------

TEST_F(GltfReader, PlainFileReadsAsWritten) {
  const TestScene scene = avatar();
  ASSERT_EQ(plain_.meshes.size(), 2u);
  EXPECT_EQ(plain_.format, "glTF 2.0");
  EXPECT_EQ(plain_.declared_unit, "metre (glTF 2.0)");
  EXPECT_EQ(plain_.declared_metres_per_unit, 1);
  EXPECT_EQ(plain_.vertex_order, "as in the file's vertex buffers");
  for (std::size_t m = 0; m < 2; ++m) {
    const SourceMesh& got = plain_.meshes[m];
    const TestMesh& want = scene.meshes[m];
    EXPECT_EQ(got.name, want.name);
    EXPECT_EQ(got.vertices, want.vertices);
    EXPECT_EQ(got.triangles, want.triangles);
    ASSERT_EQ(got.shapes.size(), want.shapes.size());
    for (std::size_t s = 0; s < want.shapes.size(); ++s) {
      EXPECT_EQ(got.shapes[s].name, want.shapes[s].name);
      EXPECT_EQ(got.shapes[s].deltas, want.shapes[s].deltas);
    }
    const std::vector<double> t = softdeca::test::expected_transform(scene, want);
    for (int k = 0; k < 16; ++k) EXPECT_NEAR(got.transform[k], t[static_cast<std::size_t>(k)], 1e-12) << want.name << " " << k;
  }
}

TEST_F(GltfReader, SparseTargetsWithoutBufferViewReadAsDense) {
  for (const std::uint32_t indices : {5121u, 5123u, 5125u}) {
    Encoding e;
    e.sparse = true;
    e.sparse_indices = indices;
    expect_same(read("sparse" + std::to_string(indices) + ".glb", e), plain_, 1e-9);
  }
  Encoding over;
  over.sparse = true;
  over.sparse_over_view = true;
  expect_same(read("sparse_over_view.glb", over), plain_, 1e-9);
  // Normalized values: within half a step of the scene's largest scale (0.01 x 2).
  Encoding bytes;
  bytes.sparse = true;
  bytes.sparse_values = 5120;
  expect_same(read("sparse_i8.glb", bytes), plain_, 0.02 * 0.5 / 127 + 1e-9);
  Encoding shorts;
  shorts.sparse = true;
  shorts.sparse_values = 5122;
  expect_same(read("sparse_i16.glb", shorts), plain_, 0.02 * 0.5 / 32767 + 1e-9);
}

TEST_F(GltfReader, MeshQuantizationReadsWithinItsStep) {
  Encoding e;
  e.quantized_positions = true;
  e.quantized_deltas = true;
  // Positions in shorts, deltas in bytes of the mesh's extent (3 units), placed at 0.01 x 2.
  expect_same(read("quantized.glb", e), plain_, 0.02 * 3 * 0.5 / 127 + 1e-9);
  Encoding positions_only;
  positions_only.quantized_positions = true;
  expect_same(read("quantized_positions.glb", positions_only), plain_, 0.02 * 3 * 0.5 / 32767 + 1e-9);
}

TEST_F(GltfReader, TargetNamesFromEachPlaceTheyAreKept) {
  for (const char* where : {"primitive", "target"}) {
    Encoding e;
    e.names = where;
    expect_same(read(std::string("names_") + where + ".glb", e), plain_, 1e-9);
  }
  Encoding none;
  none.names = "none";
  const SourceScene unnamed = read("unnamed.glb", none);
  ASSERT_EQ(unnamed.meshes[0].shapes.size(), 3u);
  EXPECT_EQ(unnamed.meshes[0].shapes[2].name, "target 2");
}

TEST_F(GltfReader, SeveralPrimitivesJoinInFileOrder) {
  Encoding e;
  e.split_head_at = 6;
  expect_same(read("split.glb", e), plain_, 1e-9);
}

TEST_F(GltfReader, PrimitivesSharingTheirVertexDataShareVertices) {
  // The head as exporters write a mesh of two materials: two primitives over one POSITION
  // accessor and the same targets, each with its own triangles (a range of one index view).
  const TestMesh head = avatar().meshes[0];
  Gltf g;
  const int position = vec3_accessor(g, g.view(bytes_of(head.vertices), 12), "5126", 10, head.vertices);
  std::vector<std::string> targets;
  for (const auto& shape : head.shapes)
    targets.push_back("{\"POSITION\":" + std::to_string(vec3_accessor(g, g.view(bytes_of(shape.deltas), 12), "5126", 10, shape.deltas)) + "}");
  const int view = g.view(bytes_of(std::vector<std::uint32_t>(head.triangles.begin(), head.triangles.end())));
  const int first = g.accessor("{\"bufferView\":" + std::to_string(view) + ",\"componentType\":5125,\"count\":24,\"type\":\"SCALAR\"}");
  const int second = g.accessor("{\"bufferView\":" + std::to_string(view) + ",\"byteOffset\":96,\"componentType\":5125,\"count\":12,\"type\":\"SCALAR\"}");
  const auto primitive = [&](int indices) {
    return "{\"attributes\":{\"POSITION\":" + std::to_string(position) + "},\"indices\":" + std::to_string(indices) + ",\"targets\":[" +
           join(targets) + "]}";
  };
  g.meshes.push_back("{\"name\":\"Head\",\"primitives\":[" + primitive(first) + "," + primitive(second) + "]}");
  g.nodes.push_back("{\"mesh\":0}");
  const SourceScene s = read_gltf(dir_.write("shared.glb", g.glb()), {});
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].vertices, head.vertices);
  EXPECT_EQ(s.meshes[0].triangles, head.triangles);
  ASSERT_EQ(s.meshes[0].shapes.size(), 3u);
  EXPECT_EQ(s.meshes[0].shapes[1].deltas, head.shapes[1].deltas);
}

TEST_F(GltfReader, StripsAndFansBecomeTrianglesAndPointsAreLeftOut) {
  // The head's tetrahedron as a strip over its own vertices, a fan of two triangles, and points.
  Gltf g;
  const std::vector<float> tetra = {2, 0, 0, 3, 0, 0, 2, 1, 0, 2, 0, 1};
  const int v = g.view(bytes_of(tetra), 12);
  const int pos = g.accessor("{\"bufferView\":" + std::to_string(v) + ",\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}");
  const int strip = g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(std::vector<std::uint16_t>{0, 1, 2, 3, 0, 1}))) +
                               ",\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}");
  g.meshes.push_back("{\"name\":\"Parts\",\"primitives\":[{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "},\"indices\":" +
                     std::to_string(strip) + ",\"mode\":5},{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
                     "},\"mode\":0},{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "},\"mode\":6}]}");
  g.nodes.push_back("{\"mesh\":0}");
  const SourceScene s = read_gltf(dir_.write("modes.glb", g.glb()), {});
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].name, "Parts");  // the mesh's name where the node has none
  EXPECT_EQ(s.meshes[0].vertex_count(), 4u);  // the primitives share their POSITION accessor
  // The strip p_i = {v_i, v_i+(1+i%2), v_i+(2-i%2)}, then the fan {v_i+1, v_i+2, v_0}.
  EXPECT_EQ(s.meshes[0].triangles, (std::vector<std::int32_t>{0, 1, 2, 1, 3, 2, 2, 3, 0, 3, 1, 0, 1, 2, 0, 2, 3, 0}));
}

TEST_F(GltfReader, DataUrisAndBuffersBesideTheFileRead) {
  // The plain avatar as .gltf: buffer 0 once as a data: URI, once as a file with a percent-escaped name.
  Gltf g;
  const TestMesh teeth = avatar().meshes[1];
  g.meshes.push_back("{\"primitives\":[" + teeth_primitive(g) + "]}");
  g.nodes.push_back("{\"name\":\"T\",\"mesh\":0}");
  std::string json = g.json();
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string base64;
  for (std::size_t i = 0; i < g.bin.size(); i += 3) {
    const std::uint32_t b = (std::uint32_t{static_cast<unsigned char>(g.bin[i])} << 16) |
                            (i + 1 < g.bin.size() ? std::uint32_t{static_cast<unsigned char>(g.bin[i + 1])} << 8 : 0) |
                            (i + 2 < g.bin.size() ? std::uint32_t{static_cast<unsigned char>(g.bin[i + 2])} : 0);
    base64 += kAlphabet[(b >> 18) & 63];
    base64 += kAlphabet[(b >> 12) & 63];
    base64 += i + 1 < g.bin.size() ? kAlphabet[(b >> 6) & 63] : '=';
    base64 += i + 2 < g.bin.size() ? kAlphabet[b & 63] : '=';
  }
  const std::string buffer = "\"buffers\":[{\"byteLength\":" + std::to_string(g.bin.size());
  const auto with_uri = [&](const std::string& uri) {
    std::string j = json;
    j.replace(j.find(buffer), buffer.size(), buffer + ",\"uri\":\"" + uri + "\"");
    return j;
  };
  const SourceScene embedded = read_gltf(dir_.write("embedded.gltf", with_uri("data:application/octet-stream;base64," + base64)), {});
  ASSERT_EQ(embedded.meshes.size(), 1u);
  EXPECT_EQ(embedded.meshes[0].vertices, teeth.vertices);
  dir_.write("sub dir/the data.bin", g.bin);
  const SourceScene beside = read_gltf(dir_.write("beside.gltf", with_uri("sub%20dir%2Fthe%20data.bin")), {});
  EXPECT_EQ(beside.meshes[0].vertices, teeth.vertices);
  EXPECT_TRUE(fails_with(dir_.write("bad64.gltf", with_uri("data:application/octet-stream;base64,@@@@")), "not base64"));
  EXPECT_TRUE(fails_with(dir_.write("short.gltf", with_uri("data:application/octet-stream;base64,AAAA")), "buffers[0]: byteLength"));
}

#if SOFTDECA_TEST_MESHOPT
TEST_F(GltfReader, MeshoptCompressedViewsReadWithoutTheirFallback) {
  ASSERT_TRUE(softdeca::avatar_import::gltf::meshopt_supported());
  Encoding e;
  e.meshopt = true;
  expect_same(read("meshopt.glb", e), plain_, 1e-9);
  Encoding quantized = e;
  quantized.quantized_positions = quantized.quantized_deltas = true;
  expect_same(read("meshopt_quantized.glb", quantized), plain_, 0.02 * 3 * 0.5 / 127 + 1e-9);
  Encoding filtered = e;
  filtered.exponential = true;  // 20-bit mantissas: relative 2^-20 of deltas up to 0.5 units, placed at 0.02
  expect_same(read("meshopt_exponential.glb", filtered), plain_, 0.02 * 0.5 * std::ldexp(1.0, -19));
}
#endif

#if SOFTDECA_TEST_DRACO
// libdraco's own streams, each method, with and without metadata (per attribute and for the
// mesh, with sub-metadata): the counts read ahead of the decoder are the mesh's.
TEST(DracoHeader, CountsOfTheEncodersStreams) {
  using softdeca::avatar_import::gltf::read_draco_counts;
  const int n = 9;  // a 3 x 3 grid of points, 8 triangles
  std::vector<float> positions;
  std::vector<std::uint32_t> triangles;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) positions.insert(positions.end(), {0.01f * x, 0.01f * y, 0.001f * x * y});
  for (std::uint32_t y = 0; y < 2; ++y)
    for (std::uint32_t x = 0; x < 2; ++x) {
      const std::uint32_t c = 3 * y + x;
      triangles.insert(triangles.end(), {c, c + 1, c + 3, c + 1, c + 4, c + 3});
    }
  for (const bool edgebreaker : {false, true})
    for (const bool metadata : {false, true}) {
      draco::Mesh mesh;
      mesh.set_num_points(n);
      draco::GeometryAttribute position;
      position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, 12, 0);
      const int id = mesh.AddAttribute(position, true, n);
      for (int i = 0; i < n; ++i)
        mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(static_cast<std::uint32_t>(i)), &positions[3 * i]);
      for (std::size_t t = 0; t < triangles.size(); t += 3)
        mesh.AddFace({draco::PointIndex(triangles[t]), draco::PointIndex(triangles[t + 1]), draco::PointIndex(triangles[t + 2])});
      if (metadata) {
        auto geometry = std::make_unique<draco::GeometryMetadata>();
        geometry->AddEntryString("exporter", "a tool");
        auto inner = std::make_unique<draco::Metadata>();
        inner->AddEntryInt("level", 2);
        auto innermost = std::make_unique<draco::Metadata>();
        innermost->AddEntryString("note", std::string(300, 'x'));
        inner->AddSubMetadata("deeper", std::move(innermost));
        geometry->AddSubMetadata("nested", std::move(inner));
        mesh.AddMetadata(std::move(geometry));
        auto on_position = std::make_unique<draco::AttributeMetadata>();
        on_position->AddEntryString("name", "POSITION");
        mesh.AddAttributeMetadata(id, std::move(on_position));
      }
      draco::Encoder encoder;
      encoder.SetEncodingMethod(edgebreaker ? draco::MESH_EDGEBREAKER_ENCODING : draco::MESH_SEQUENTIAL_ENCODING);
      draco::EncoderBuffer buffer;
      ASSERT_TRUE(encoder.EncodeMeshToBuffer(mesh, &buffer).ok());
      const std::string stream(buffer.data(), buffer.size());
      const auto counts = read_draco_counts(stream, "test");
      EXPECT_EQ(counts.edgebreaker, edgebreaker);
      EXPECT_EQ(counts.faces, triangles.size() / 3) << edgebreaker << metadata;
      EXPECT_EQ(counts.vertices, static_cast<std::uint64_t>(n)) << edgebreaker << metadata;
      // Cut short before its counts end, a stream is refused in words (never read past its
      // end); from there on the counts are read alike.
      std::size_t shortest = 0;
      for (; shortest < stream.size(); ++shortest) {
        try {
          EXPECT_EQ(read_draco_counts(std::string_view(stream).substr(0, shortest), "test").faces, counts.faces);
          break;
        } catch (const std::runtime_error& e) {
          EXPECT_NE(std::string(e.what()).find("its Draco"), std::string::npos) << e.what();
        }
      }
      EXPECT_GE(shortest, metadata ? 40u : 13u);
      EXPECT_LT(shortest, stream.size());
    }
}

TEST_F(GltfReader, DracoPrimitivesReadWithPlainMorphTargets) {
  ASSERT_TRUE(softdeca::avatar_import::gltf::draco_supported());
  Encoding e;
  e.draco = true;
  expect_same(read("draco.glb", e), plain_, 1e-9);
}
#endif

// gltfpack on the PATH, "" when it is not installed.
std::string gltfpack_program() {
  const char* path = std::getenv("PATH");
  for (std::string dirs = path ? path : ""; !dirs.empty();) {
    const std::size_t colon = dirs.find(':');
    const std::string candidate = dirs.substr(0, colon) + "/gltfpack";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    dirs = colon == std::string::npos ? "" : dirs.substr(colon + 1);
  }
  return "";
}

// `input` through gltfpack (compressed with EXT_meshopt_compression where this build decodes
// it, else quantized only; named nodes and meshes kept), read back.
SourceScene gltfpacked(const TempDir& dir, const std::string& input) {
  const std::string packed = dir.file("packed.glb");
  const std::string compress = softdeca::avatar_import::gltf::meshopt_supported() ? " -cc" : "";
  const std::string command = gltfpack_program() + " -i '" + dir.file(input) + "' -o '" + packed + "'" + compress + " -kn -km > '" +
                              dir.file("gltfpack.log") + "' 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return read_gltf(packed, {});
}

// gltfpack reorders vertices and quantizes positions to 14 bits of each mesh's extent
// (`extent`, placed): every placed vertex of `want` is found in `got`, with its shapes' deltas,
// within that step.
void expect_same_points(const SourceScene& got, const SourceScene& want, double extent) {
  const double step = 2 * extent / (1 << 14);
  for (const SourceMesh& w : want.meshes) {
    const auto it = std::find_if(got.meshes.begin(), got.meshes.end(), [&](const SourceMesh& m) { return m.name == w.name; });
    ASSERT_NE(it, got.meshes.end()) << w.name;
    ASSERT_EQ(it->vertex_count(), w.vertex_count()) << w.name;
    EXPECT_EQ(it->triangles.size(), w.triangles.size());
    for (std::size_t i = 0; i < w.vertex_count(); ++i) {
      const auto p = placed(w, i, w.vertices, true);
      std::size_t nearest = 0;
      double best = 1e30;
      for (std::size_t j = 0; j < it->vertex_count(); ++j) {
        const auto g = placed(*it, j, it->vertices, true);
        const double d = std::hypot(g[0] - p[0], g[1] - p[1], g[2] - p[2]);
        if (d < best) best = d, nearest = j;
      }
      EXPECT_LT(best, step) << w.name << " vertex " << i;
      for (const SourceShape& ws : w.shapes) {
        const SourceShape* gs = shape_named(*it, ws.name);
        ASSERT_NE(gs, nullptr) << w.name << " lacks " << ws.name;
        const auto a = placed(*it, nearest, gs->deltas, false), b = placed(w, i, ws.deltas, false);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], step) << w.name << " " << ws.name << " vertex " << i;
      }
    }
  }
}

TEST_F(GltfReader, GltfpackOutputReads) {
  if (gltfpack_program().empty()) GTEST_SKIP() << "gltfpack is not installed (.ci/setup installs it)";
  expect_same_points(gltfpacked(dir_, "plain.glb"), plain_, 3 * 0.02);
}

TEST_F(GltfReader, GltfpackOutputOfASkinnedMeshReads) {
  // gltfpack cannot put a skinned mesh's dequantization in its node (the specification ignores
  // that transform): it goes into the inverse bind matrices, which place the mesh here.
  if (gltfpack_program().empty()) GTEST_SKIP() << "gltfpack is not installed (.ci/setup installs it)";
  const TestMesh teeth = avatar().meshes[1];
  Gltf g;
  const int joints = g.accessor("{\"bufferView\":" + std::to_string(g.view(std::string(16, '\0'), 4)) +
                                ",\"componentType\":5121,\"count\":4,\"type\":\"VEC4\"}");
  std::vector<float> weight_data(16, 0.0f), bind(16, 0.0f);
  for (int v = 0; v < 4; ++v) weight_data[4 * static_cast<std::size_t>(v)] = 1;
  bind[0] = bind[5] = bind[10] = bind[15] = 1;
  bind[13] = -145;  // column-major: the jaw's move back
  const int weights = g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(weight_data), 16)) +
                                 ",\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"}");
  const int ibm = g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(bind))) + ",\"componentType\":5126,\"count\":1,\"type\":\"MAT4\"}");
  const int target = vec3_accessor(g, g.view(bytes_of(teeth.shapes[0].deltas), 12), "5126", 4, teeth.shapes[0].deltas);
  std::string primitive = teeth_primitive(g, ",\"targets\":[{\"POSITION\":" + std::to_string(target) + "}]");
  primitive.replace(primitive.find("},\"indices\""), 2, ",\"JOINTS_0\":" + std::to_string(joints) + ",\"WEIGHTS_0\":" + std::to_string(weights) + "},");
  g.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[" + primitive + "],\"extras\":{\"targetNames\":[\"jawOpen\"]}}");
  g.nodes = {"{\"name\":\"Armature\",\"scale\":[0.01,0.01,0.01],\"children\":[1,2]}", "{\"name\":\"Teeth\",\"mesh\":0,\"skin\":0}",
             "{\"name\":\"jaw\",\"translation\":[0,145,0]}"};
  g.root_members = ",\"skins\":[{\"joints\":[2],\"inverseBindMatrices\":" + std::to_string(ibm) + "}]";
  const SourceScene plain = read_gltf(dir_.write("skinned.glb", g.glb()), {});
  ASSERT_EQ(plain.meshes.size(), 1u);
  EXPECT_EQ(plain.meshes[0].transform[0], 0.01);  // the joint times its inverse bind matrix: the armature's scale
  EXPECT_EQ(plain.meshes[0].transform[7], 0);
  expect_same_points(gltfpacked(dir_, "skinned.glb"), plain, 0.01);
}

// ---- VRM expressions -----------------------------------------------------------------------

TEST_F(GltfReader, VrmBlendShapeGroupsNameShapesOverUnnamedTargets) {
  Encoding e;
  e.names = "none";
  // VRM 0.x: mesh 0's targets 0 and 1 under ARKit names (one at full weight, one as the sum of
  // halves), a group named as a target already is (not added), the teeth's target by preset name.
  e.root_members = ",\"extensions\":{\"VRM\":{\"blendShapeMaster\":{\"blendShapeGroups\":["
                   "{\"name\":\"eyeBlinkLeft\",\"presetName\":\"blink_l\",\"binds\":[{\"mesh\":0,\"index\":0,\"weight\":100}]},"
                   "{\"name\":\"mouthSmileLeft\",\"presetName\":\"unknown\",\"binds\":[{\"mesh\":0,\"index\":2,\"weight\":50},{\"mesh\":0,\"index\":2,\"weight\":50}]},"
                   "{\"name\":\"target 1\",\"binds\":[{\"mesh\":0,\"index\":0,\"weight\":100}]},"
                   "{\"name\":\"\",\"presetName\":\"jawOpen\",\"binds\":[{\"mesh\":0,\"index\":1,\"weight\":100},{\"mesh\":1,\"index\":0,\"weight\":100}]}]}}}";
  const SourceScene vrm = read_gltf(dir_.write("avatar.vrm", write(avatar(), e)), {});
  expect_same(vrm, plain_, 1e-9);
  EXPECT_EQ(vrm.meshes[0].shapes.size(), 6u);  // 3 targets + 3 groups ("target 1" is a target's name)
  EXPECT_EQ(vrm.meshes[1].shapes.size(), 2u);
}

TEST_F(GltfReader, Vrm1ExpressionsNameShapesByNode) {
  Encoding e;
  e.names = "none";
  // VRM 1.0: node 1 is the head, node 2 the teeth; weights 0 to 1.
  e.root_members = ",\"extensions\":{\"VRMC_vrm\":{\"specVersion\":\"1.0\",\"expressions\":{"
                   "\"preset\":{\"blinkLeft\":{\"morphTargetBinds\":[{\"node\":1,\"index\":0,\"weight\":1}]},"
                   "\"aa\":{\"morphTargetBinds\":[{\"node\":1,\"index\":1,\"weight\":1},{\"node\":2,\"index\":0,\"weight\":1}]}},"
                   "\"custom\":{\"eyeBlinkLeft\":{\"morphTargetBinds\":[{\"node\":1,\"index\":0,\"weight\":1}]},"
                   "\"mouthSmileLeft\":{\"morphTargetBinds\":[{\"node\":1,\"index\":2,\"weight\":0.25},{\"node\":1,\"index\":2,\"weight\":0.75}]},"
                   "\"jawOpen\":{\"morphTargetBinds\":[{\"node\":1,\"index\":1,\"weight\":1},{\"node\":2,\"index\":0,\"weight\":1}]}}}}}";
  const SourceScene vrm = read_gltf(dir_.write("avatar1.vrm", write(avatar(), e)), {});
  expect_same(vrm, plain_, 1e-9);
  ASSERT_NE(shape_named(vrm.meshes[0], "blinkLeft"), nullptr);
  EXPECT_EQ(shape_named(vrm.meshes[0], "blinkLeft")->deltas, shape_named(plain_.meshes[0], "eyeBlinkLeft")->deltas);

  Encoding bad = e;
  bad.root_members = ",\"extensions\":{\"VRMC_vrm\":{\"expressions\":{\"custom\":{\"x\":{\"morphTargetBinds\":[{\"node\":1,\"index\":7,\"weight\":1}]}}}}}";
  EXPECT_TRUE(fails_with(dir_.write("bad.vrm", write(avatar(), bad)), "morphTargetBinds[0]: index 7 is not one of the 3 morph targets of mesh 'Head'"));
}

// ---- skins ---------------------------------------------------------------------------------

TEST_F(GltfReader, ASkinnedMeshIsPlacedByItsJointsWhereTheyAgree) {
  // The teeth's node carries a transform the specification says to ignore; its joints (one
  // scaled by 3, a child of it moved by 1 whose inverse bind matrix moves back) place it.
  const auto skinned = [&](const std::string& name, float bind_back) {
    Gltf g;
    const std::string primitive = teeth_primitive(g);
    std::vector<float> binds(32, 0.0f);
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 4; ++k) binds[static_cast<std::size_t>(16 * j + 5 * k)] = 1;
    binds[16 + 12] = -bind_back;  // column-major: the translation is the last column
    const int ibm = g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(binds))) + ",\"componentType\":5126,\"count\":2,\"type\":\"MAT4\"}");
    g.meshes.push_back("{\"primitives\":[" + primitive + "]}");
    g.nodes = {"{\"children\":[1,2]}", "{\"name\":\"T\",\"mesh\":0,\"skin\":0,\"translation\":[5,5,5]}",
               "{\"name\":\"jaw\",\"scale\":[3,3,3],\"children\":[3]}", "{\"name\":\"tip\",\"translation\":[1,0,0]}"};
    g.root_members = ",\"skins\":[{\"joints\":[2,3],\"inverseBindMatrices\":" + std::to_string(ibm) + "}]";
    return read_gltf(dir_.write(name, g.glb()), {});
  };
  const SourceScene bound = skinned("bound.glb", 1);
  ASSERT_EQ(bound.meshes.size(), 1u);
  EXPECT_EQ(bound.meshes[0].transform[0], 3);
  EXPECT_EQ(bound.meshes[0].transform[3], 0);
  // Joints posed away from their bind pose would deform the mesh: it is placed by its node.
  const SourceScene posed = skinned("posed.glb", 0);
  EXPECT_EQ(posed.meshes[0].transform[0], 1);
  EXPECT_EQ(posed.meshes[0].transform[3], 5);
}

// ---- nodes and scenes ----------------------------------------------------------------------

TEST_F(GltfReader, MatricesScenesAndTargetsWithoutPositions) {
  Gltf g;
  g.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[" + teeth_primitive(g, ",\"targets\":[{\"NORMAL\":0}]") + "]}");
  // Column-major: a scale of 2 and a move of (1, 2, 3).
  g.nodes = {"{\"name\":\"A\",\"mesh\":0,\"matrix\":[2,0,0,0,0,2,0,0,0,0,2,0,1,2,3,1]}", "{\"name\":\"B\",\"mesh\":0}"};
  std::string json = g.json();
  // No scenes: every root node.
  json.replace(json.find("\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"), std::strlen("\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"), "");
  const SourceScene s = read_gltf(dir_.write("matrix.glb", Gltf::glb_of(json, g.bin)), {});
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].name, "A");
  EXPECT_EQ(s.meshes[0].transform[0], 2);
  EXPECT_EQ(s.meshes[0].transform[7], 2);
  EXPECT_EQ(s.meshes[0].transform[11], 3);
  EXPECT_EQ(s.meshes[1].name, "B");
  ASSERT_EQ(s.meshes[1].shapes.size(), 1u);
  EXPECT_EQ(s.meshes[1].shapes[0].deltas, std::vector<float>(12, 0.0f));  // a target of normals alone moves nothing
}

// ---- hostile files -------------------------------------------------------------------------

class GltfHostile : public ::testing::Test {
 protected:
  TempDir dir_{"gltf-hostile"};
  // A small valid file whose JSON `edit` changes.
  std::string write_edited(const std::string& name, const std::function<void(std::string&)>& edit, bool binary = true) {
    Gltf g;
    const TestMesh teeth = avatar().meshes[1];
    const int pos = g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(teeth.vertices), 12)) +
                               ",\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}");
    const int idx = g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(std::vector<std::uint32_t>{0, 1, 2, 0, 1, 3}))) +
                               ",\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"}");
    g.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "},\"indices\":" +
                       std::to_string(idx) + "}]}");
    g.nodes.push_back("{\"name\":\"T\",\"mesh\":0}");
    std::string json = g.json();
    edit(json);
    return dir_.write(name, binary ? Gltf::glb_of(json, g.bin) : json);
  }
  static void replace(std::string& json, const std::string& from, const std::string& to) {
    const std::size_t at = json.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    json.replace(at, from.size(), to);
  }
};

TEST_F(GltfHostile, TheUneditedFileReads) { EXPECT_EQ(error_of(write_edited("ok.glb", [](std::string&) {})), ""); }

TEST_F(GltfHostile, OffsetsNearTwoToThe64AreRefusedNotWrapped) {
  for (const char* offset : {"18446744073709486080", "18446744073709551612"}) {
    const std::string path = write_edited("offset.glb", [&](std::string& j) {
      replace(j, "\"componentType\":5126,\"count\":4", std::string("\"byteOffset\":") + offset + ",\"componentType\":5126,\"count\":4");
    });
    EXPECT_TRUE(fails_with(path, "accessors[0].byteOffset"));
    const std::string view = write_edited("view_offset.glb", [&](std::string& j) {
      replace(j, "{\"buffer\":0,\"byteOffset\":0", std::string("{\"buffer\":0,\"byteOffset\":") + offset);
    });
    EXPECT_TRUE(fails_with(view, "bufferViews[0].byteOffset"));
  }
  // Within 2^53 but past the view: the sum is checked, not wrapped.
  const std::string past = write_edited("past.glb", [&](std::string& j) {
    replace(j, "\"componentType\":5126,\"count\":4", "\"byteOffset\":9007199254740988,\"componentType\":5126,\"count\":4");
  });
  EXPECT_TRUE(fails_with(past, "accessors[0]: 4 elements from byteOffset 9007199254740988 do not fit the 48 bytes of bufferViews[0]"));
}

TEST_F(GltfHostile, AChunkLongerThanTheFileIsRefused) {
  std::string glb = "glTF";
  const auto put = [&](std::uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
  put(2);
  put(24);
  put(0xFFFFFFF0u);
  glb += "JSON{}  ";
  const std::string path = dir_.write("chunk.glb", glb);
  EXPECT_TRUE(fails_with(path, "chunk 0: 4294967280 bytes from byte 20, past the end of the file's 24"));
  std::string longer = glb;
  longer.replace(8, 4, std::string("\xF0\xFF\xFF\xFF", 4));
  EXPECT_TRUE(fails_with(dir_.write("header.glb", longer), "its header says 4294967280 bytes, but the file has 24"));
}

TEST_F(GltfHostile, UrisThatLeaveTheFolderAreRefused) {
  const std::filesystem::path outside = dir_.dir.parent_path() / ("softdeca-outside-" + std::to_string(::getpid()) + ".bin");
  { std::ofstream(outside) << std::string(64, '\0'); }
  const std::string inner = "inner";
  std::filesystem::create_directories(dir_.dir / inner);
  const auto with_uri = [&](const std::string& name, const std::string& uri) {
    return write_edited(inner + "/" + name, [&](std::string& j) { replace(j, "\"buffers\":[{\"byteLength\":72", "\"buffers\":[{\"byteLength\":72,\"uri\":\"" + uri + "\""); },
                        false);
  };
  EXPECT_TRUE(fails_with(with_uri("up.gltf", "../../" + outside.filename().string()), "leads out of the avatar's folder"));
  EXPECT_TRUE(fails_with(with_uri("absolute.gltf", outside.string()), "is an absolute path"));
  EXPECT_TRUE(fails_with(with_uri("file.gltf", "file://" + outside.string()), "names a drive or a scheme"));
  EXPECT_TRUE(fails_with(with_uri("escaped.gltf", "..%2F..%2F" + outside.filename().string()), "leads out of the avatar's folder"));
  EXPECT_TRUE(fails_with(with_uri("escaped_root.gltf", "%2Fetc%2Fpasswd"), "is an absolute path"));
  ASSERT_EQ(::mkfifo((dir_.dir / inner / "fifo.bin").c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(fails_with(with_uri("fifo.gltf", "fifo.bin"), "is a FIFO"));
  EXPECT_LT(seconds_since(start), 5.0);
  std::filesystem::create_symlink(outside, dir_.dir / inner / "link.bin");
  EXPECT_TRUE(fails_with(with_uri("link.gltf", "link.bin"), "is a symbolic link"));
  std::filesystem::remove(outside);
}

TEST_F(GltfHostile, DeepOrSharedNodesAreRefusedFast) {
  // 100,000 nodes each the child of the one before.
  const auto start = std::chrono::steady_clock::now();
  const std::string deep = write_edited("deep.glb", [](std::string& j) {
    std::string nodes = "\"nodes\":[{\"name\":\"T\",\"mesh\":0,\"children\":[1]}";
    for (int i = 1; i < 99999; ++i) nodes += ",{\"children\":[" + std::to_string(i + 1) + "]}";
    nodes += ",{}]";
    replace(j, "\"nodes\":[{\"name\":\"T\",\"mesh\":0}]", nodes);
  });
  EXPECT_TRUE(fails_with(deep, "nested 257 deep, more than the 256"));
  EXPECT_LT(seconds_since(start), 5.0);
  // A diamond: two parents of one node.
  const std::string diamond = write_edited("diamond.glb", [](std::string& j) {
    replace(j, "\"scenes\":[{\"nodes\":[0]}]", "\"scenes\":[{\"nodes\":[1,2]}]");
    replace(j, "\"nodes\":[{\"name\":\"T\",\"mesh\":0}]", "\"nodes\":[{\"name\":\"T\",\"mesh\":0},{\"children\":[0]},{\"children\":[0]}]");
  });
  EXPECT_TRUE(fails_with(diamond, "nodes[0]: is a child of both nodes[1] and nodes[2]"));
  const std::string cycle = write_edited("cycle.glb", [](std::string& j) {
    replace(j, "\"scenes\":[{\"nodes\":[0]}]", "\"scenes\":[{\"nodes\":[]}]");
    replace(j, "\"nodes\":[{\"name\":\"T\",\"mesh\":0}]", "\"nodes\":[{\"name\":\"T\",\"mesh\":0,\"children\":[1]},{\"children\":[0]}]");
  });
  EXPECT_TRUE(fails_with(cycle, "is its own ancestor"));
  // A mesh of a million vertices (zeros: no bufferView) placed by 300 nodes.
  const auto bomb_start = std::chrono::steady_clock::now();
  const std::string bomb = write_edited("bomb.glb", [](std::string& j) {
    replace(j, "{\"bufferView\":0,\"componentType\":5126,\"count\":4", "{\"componentType\":5126,\"count\":1000000");
    replace(j, ",\"indices\":1", "");
    std::string nodes = "\"nodes\":[{\"children\":[";
    for (int i = 1; i <= 300; ++i) nodes += (i > 1 ? "," : "") + std::to_string(i);
    nodes += "]}";
    for (int i = 1; i <= 300; ++i) nodes += ",{\"mesh\":0}";
    replace(j, "\"nodes\":[{\"name\":\"T\",\"mesh\":0}]", nodes + "]");
  });
  EXPECT_TRUE(fails_with(bomb, "its scene places more than 8000000 vertices"));
  EXPECT_LT(seconds_since(bomb_start), 2.0);
}

TEST_F(GltfHostile, JsonNestedAMillionDeepIsRefusedByDepth) {
  const auto start = std::chrono::steady_clock::now();
  const std::string path = dir_.write("nested.gltf", "{\"a\":" + std::string(1000000, '[') + std::string(1000000, ']') + "}");
  EXPECT_TRUE(fails_with(path, "nesting"));
  EXPECT_LT(seconds_since(start), 2.0);
  ImportLimits few;
  few.max_json_values = 10;
  EXPECT_TRUE(fails_with(write_edited("values.glb", [](std::string&) {}), "more than the 10 values", few));
}

TEST_F(GltfHostile, BadStridesAndIndicesAreRefused) {
  const std::string stride = write_edited("stride.glb", [](std::string& j) {
    replace(j, "\"byteLength\":48,\"byteStride\":12", "\"byteLength\":48,\"byteStride\":4");
  });
  EXPECT_TRUE(fails_with(stride, "accessors[0]: its bufferView's byteStride 4 is less than its 12-byte elements"));
  Gltf g;
  const TestMesh teeth = avatar().meshes[1];
  g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(teeth.vertices), 12)) + ",\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}");
  g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(std::vector<std::uint32_t>{0, 1, 9}))) + ",\"componentType\":5125,\"count\":3,\"type\":\"SCALAR\"}");
  g.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}");
  g.nodes.push_back("{\"mesh\":0}");
  EXPECT_TRUE(fails_with(dir_.write("index.glb", g.glb()), "mesh 'Teeth' primitive 0: its vertex index 9 (number 2) is not below its 4 vertices"));
}

TEST_F(GltfHostile, SparseIndicesMustIncrease) {
  Gltf g;
  const std::string primitive = teeth_primitive(g, ",\"targets\":[{\"POSITION\":2}]");
  const int iv = g.view(bytes_of(std::vector<std::uint16_t>{2, 1}));
  const int vv = g.view(bytes_of(std::vector<float>(6, 0.5f)));
  g.accessor("{\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"sparse\":{\"count\":2,\"indices\":{\"bufferView\":" + std::to_string(iv) +
             ",\"componentType\":5123},\"values\":{\"bufferView\":" + std::to_string(vv) + "}}}");
  g.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[" + primitive + "]}");
  g.nodes.push_back("{\"mesh\":0}");
  EXPECT_TRUE(fails_with(dir_.write("sparse.glb", g.glb()), "accessors[2] (morph target 0 of meshes[0].primitives[0]): its sparse indices are not increasing (1 after 2)"));
}

TEST_F(GltfHostile, ManyTargetsSharingOneAccessorAreBounded) {
  const auto targets = [](std::string& j) {
    std::string list;
    for (int t = 0; t < 5000; ++t) list += (t ? "," : "") + std::string("{\"POSITION\":0}");
    replace(j, "},\"indices\":1}", "},\"indices\":1,\"targets\":[" + list + "]}");
  };
  const auto start = std::chrono::steady_clock::now();
  const std::string path = write_edited("targets.glb", targets);
  EXPECT_TRUE(fails_with(path, "mesh 'Teeth': 5000 morph targets, more than the 1024"));
  ImportLimits many;
  many.max_morph_targets = 10000;
  many.max_decoded_bytes = 100000;  // 5000 x 48 bytes of deltas is more
  EXPECT_TRUE(fails_with(path, "past the 100000 bytes", many));
  EXPECT_LT(seconds_since(start), 2.0);
}

TEST_F(GltfHostile, ShortBuffersAndBadVersionsAreRefused) {
  EXPECT_TRUE(fails_with(write_edited("long_buffer.glb", [](std::string& j) { replace(j, "\"buffers\":[{\"byteLength\":72", "\"buffers\":[{\"byteLength\":720"); }),
               "buffers[0]: byteLength 720, but its data has 72 bytes"));
  EXPECT_TRUE(fails_with(write_edited("view_past.glb", [](std::string& j) { replace(j, "\"byteLength\":48,", "\"byteLength\":480,"); }),
               "bufferViews[0]: 480 bytes from byteOffset 0 run past the 72 bytes of buffers[0]"));
  EXPECT_TRUE(fails_with(write_edited("v1.glb", [](std::string& j) { replace(j, "\"version\":\"2.0\"", "\"version\":\"1.0\""); }),
               "asset.version: '1.0': only glTF 2.0 is read"));
}

TEST_F(GltfHostile, PrimitivesWhoseTargetsDisagreeAreRefused) {
  Gltf g;
  const std::string first = teeth_primitive(g, ",\"targets\":[{\"POSITION\":0},{\"POSITION\":0}]");
  const std::string second = teeth_primitive(g, ",\"targets\":[{\"POSITION\":0}]");
  g.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[" + first + "," + second + "]}");
  g.nodes.push_back("{\"mesh\":0}");
  EXPECT_TRUE(fails_with(dir_.write("targets.glb", g.glb()), "mesh 'Teeth': primitive 1 has 1 morph targets, primitive 0 2"));
}

TEST_F(GltfHostile, VrmExpressionsAreBounded) {
  std::string groups;
  for (int k = 0; k < 2000; ++k)
    groups += std::string(k ? "," : "") + "{\"name\":\"g" + std::to_string(k) + "\",\"binds\":[{\"mesh\":0,\"index\":0,\"weight\":100}]}";
  const std::string path = write_edited("groups.vrm", [&](std::string& j) {
    replace(j, "},\"indices\":1}", "},\"indices\":1,\"targets\":[{\"POSITION\":0}]}");
    j.insert(j.size() - 1, ",\"extensions\":{\"VRM\":{\"blendShapeMaster\":{\"blendShapeGroups\":[" + groups + "]}}}");
  });
  EXPECT_TRUE(fails_with(path, "mesh 'Teeth': more than 1024 VRM expressions bind its morph targets"));
  ImportLimits tight;
  tight.max_decoded_bytes = 20000;
  EXPECT_TRUE(fails_with(path, "the VRM expression 'g", tight));
}

TEST_F(GltfHostile, CompressedDataThatDoesNotDecodeIsRefused) {
  // Garbage where compressed data belongs, and no uncompressed copy: a build with the decoders
  // says the data does not decode, a build without them that it cannot decode the extension.
  using softdeca::avatar_import::gltf::draco_supported;
  using softdeca::avatar_import::gltf::meshopt_supported;
  Gltf g;
  const int garbage = g.view(std::string(64, '\x5a'));
  g.views[static_cast<std::size_t>(garbage)] =
      "{\"buffer\":1,\"byteLength\":48,\"byteStride\":12,\"extensions\":{\"EXT_meshopt_compression\":{\"buffer\":0,\"byteLength\":64,"
      "\"byteStride\":12,\"count\":4,\"mode\":\"ATTRIBUTES\"}}}";
  g.fallback_length = 48;
  g.accessor("{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}");
  g.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}");
  g.accessor("{\"bufferView\":" + std::to_string(g.view(bytes_of(std::vector<std::uint32_t>{0, 1, 2}))) +
             ",\"componentType\":5125,\"count\":3,\"type\":\"SCALAR\"}");
  g.nodes.push_back("{\"mesh\":0}");
  EXPECT_TRUE(fails_with(dir_.write("meshopt.glb", g.glb()),
                         meshopt_supported() ? "bufferViews[0]: its EXT_meshopt_compression data does not decode"
                                             : "bufferViews[0]: this build cannot decode EXT_meshopt_compression"));
  Gltf d;
  const int view = d.view(std::string(64, '\x5a'));
  d.accessor("{\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}");
  d.accessor("{\"componentType\":5125,\"count\":3,\"type\":\"SCALAR\"}");
  d.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"extensions\":"
                     "{\"KHR_draco_mesh_compression\":{\"bufferView\":" + std::to_string(view) + ",\"attributes\":{\"POSITION\":0}}}}]}");
  d.nodes.push_back("{\"mesh\":0}");
  EXPECT_TRUE(fails_with(dir_.write("draco.glb", d.glb()),
                         draco_supported() ? "its KHR_draco_mesh_compression data is not a Draco stream"
                                           : "meshes[0].primitives[0]: this build cannot decode KHR_draco_mesh_compression"));
}

#if SOFTDECA_TEST_DRACO
TEST_F(GltfHostile, DracoCountsBeyondTheAccessorsAreRefusedBeforeDecoding) {
  // A stream of 80 bytes declaring four billion points (sequential) or a billion faces
  // (edgebreaker): refused by its declared counts, before libdraco sizes anything by them.
  auto leb128 = [](std::uint64_t v) {
    std::string out;
    do {
      const auto b = static_cast<unsigned char>(v & 0x7F);
      v >>= 7;
      out += static_cast<char>(b | (v ? 0x80 : 0));
    } while (v);
    return out;
  };
  struct Case {
    bool edgebreaker;
    std::uint64_t vertices, faces;
    const char* says;
  };
  for (const Case c : {Case{false, 0xFFFFFFF0u, 1, "declares 4294967280 vertices, more than its POSITION accessor's 3"},
                       Case{true, 3, 0x3FFFFFFFu, "declares 1073741823 faces, more than the 1 its indices accessor holds"}}) {
    std::string stream = std::string("DRACO") + '\x02' + '\x02' + '\x01' + (c.edgebreaker ? '\x01' : '\x00') + std::string(2, '\0');
    stream += c.edgebreaker ? std::string(1, '\0') + leb128(c.vertices) + leb128(c.faces) : leb128(c.faces) + leb128(c.vertices);
    stream += std::string(64, '\x5a');
    Gltf d;
    const int view = d.view(stream);
    d.accessor("{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}");
    d.accessor("{\"componentType\":5125,\"count\":3,\"type\":\"SCALAR\"}");
    d.meshes.push_back("{\"name\":\"Teeth\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"extensions\":"
                       "{\"KHR_draco_mesh_compression\":{\"bufferView\":" + std::to_string(view) + ",\"attributes\":{\"POSITION\":0}}}}]}");
    d.nodes.push_back("{\"mesh\":0}");
    EXPECT_TRUE(fails_with(dir_.write("declares.glb", d.glb()), c.says));
  }
}
#endif

#ifndef SOFTDECA_GLTF_DAMAGED_FILES
#define SOFTDECA_GLTF_DAMAGED_FILES 300
#endif
TEST_F(GltfHostile, DamagedFilesGiveErrorsNotCrashes) {
  constexpr int kDamaged = SOFTDECA_GLTF_DAMAGED_FILES;  // per encoding
  // Each encoding of the avatar with a few random bytes changed (in its JSON or its binary data)
  // or cut short: read whole or refused with an error naming the file, never a crash.
  std::vector<Encoding> encodings(4);
  encodings[1].sparse = encodings[1].quantized_positions = true;
  encodings[2].meshopt = softdeca::avatar_import::gltf::meshopt_supported();
  encodings[3].draco = softdeca::avatar_import::gltf::draco_supported();
  std::uint64_t state = 12345;
  const auto next = [&] { return (state = state * 6364136223846793005ULL + 1442695040888963407ULL) >> 33; };
  int refused = 0, read = 0;
  for (const Encoding& e : encodings) {
    const std::string clean = write(avatar(), e);
    for (int k = 0; k < kDamaged; ++k) {
      std::string bytes = clean;
      if (k % 10 == 9) {
        bytes.resize(12 + next() % (bytes.size() - 12));
      } else {
        for (int flips = 1 + static_cast<int>(next() % 4); flips > 0; --flips)
          bytes[12 + next() % (bytes.size() - 12)] = static_cast<char>(next());
      }
      const std::string path = dir_.write("damaged.glb", bytes);
      const std::string error = error_of(path);
      if (error.empty()) {
        ++read;
      } else {
        ++refused;
        EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
      }
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(read, 0);
}

TEST(GltfBuild, CompressionSupportIsReported) {
#if SOFTDECA_TEST_MESHOPT
  EXPECT_TRUE(softdeca::avatar_import::gltf::meshopt_supported());
#endif
#if SOFTDECA_TEST_DRACO
  EXPECT_TRUE(softdeca::avatar_import::gltf::draco_supported());
#endif
}
