#include "gltf_meshes.h"

#include <algorithm>
#include <map>
#include <optional>
#include <set>

#include "gltf_draco.h"
#include "gltf_draco_header.h"

namespace softdeca::avatar_import::gltf {

namespace {
std::string text(std::uint64_t n) { return std::to_string(n); }

constexpr std::uint64_t kTriangles = 4, kTriangleStrip = 5, kTriangleFan = 6;

// A primitive that makes triangles, as the JSON states it, before anything is decoded.
struct Primitive {
  std::size_t number = 0;  // its index in mesh.primitives
  std::string where;       // "meshes[0].primitives[1]"
  std::uint64_t mode = kTriangles;
  std::size_t position = 0;
  std::optional<std::size_t> indices;
  std::optional<Object> draco;
  const std::vector<Json>* targets = nullptr;
  std::size_t target_count() const { return targets ? targets->size() : 0; }
};

std::vector<Primitive> triangle_primitives(Document& doc, const Object& mesh) {
  const std::vector<Json>& list = mesh.array("primitives");
  if (list.empty()) mesh.fail("has no primitives");
  std::vector<Primitive> out;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const Object p(list[k], mesh.at("primitives") + "[" + text(k) + "]");
    Primitive prim;
    prim.number = k;
    prim.where = p.where();
    prim.mode = p.size_or("mode", kTriangles);
    if (prim.mode > kTriangleFan) p.fail("mode " + text(prim.mode) + " is not one of 0 to 6");
    if (prim.mode < kTriangles) continue;  // points and lines: no surface
    const std::optional<std::size_t> position = p.object("attributes").optional_index("POSITION", doc.count("accessors"), "accessors");
    if (!position) continue;  // nothing to draw, as the specification says
    prim.position = *position;
    prim.indices = p.optional_index("indices", doc.count("accessors"), "accessors");
    if (const auto ext = p.optional_object("extensions")) prim.draco = ext->optional_object("KHR_draco_mesh_compression");
    prim.targets = p.optional_array("targets");
    out.push_back(std::move(prim));
  }
  return out;
}

std::string label_of(const std::string& name, std::size_t index) {
  return name.empty() ? "meshes[" + text(index) + "]" : "mesh '" + name + "'";
}

// The names of `count` morph targets: mesh.extras.targetNames, else the first primitive's
// extras.targetNames, else each target's extras.name, else "target <n>".
std::vector<std::string> target_names(const Object& mesh, const std::vector<Primitive>& primitives, std::size_t count) {
  std::vector<std::string> names(count);
  const auto names_in = [&](const Object& holder) {
    const Json* extras = holder.find("extras");  // extras may hold anything: only an object's targetNames is read
    if (!extras || !extras->is_object()) return false;
    const Object e(*extras, holder.at("extras"));
    const std::vector<Json>* list = e.optional_array("targetNames");
    if (!list) return false;
    if (list->size() != count)
      throw Problem(e.at("targetNames"), "lists " + text(list->size()) + " names for " + text(count) + " morph targets");
    for (std::size_t t = 0; t < count; ++t) names[t] = as_string((*list)[t], e.at("targetNames") + "[" + text(t) + "]");
    return true;
  };
  if (count == 0 || names_in(mesh)) return names;
  if (names_in(Object(mesh.array("primitives")[0], mesh.at("primitives") + "[0]"))) return names;
  for (std::size_t t = 0; t < count; ++t) {
    const Object target((*primitives[0].targets)[t], primitives[0].where + ".targets[" + text(t) + "]");
    const Json* extras = target.find("extras");
    if (extras && extras->is_object()) names[t] = Object(*extras, target.at("extras")).string_or("name", "");
    if (names[t].empty()) names[t] = "target " + text(t);
  }
  return names;
}

// The triangles the indices `v` make in `mode`, offset by `base`. Strips and fans follow the
// specification's order (p_i = {v_i, v_i+(1+i%2), v_i+(2-i%2)}; fans {v_i+1, v_i+2, v_0}), their
// degenerate joining triangles dropped.
void append_triangles(std::uint64_t mode, const std::vector<std::uint32_t>& v, std::int32_t base, std::vector<std::int32_t>& out,
                      const std::string& where) {
  const std::size_t n = v.size();
  const auto put = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, bool keep_degenerate) {
    if (!keep_degenerate && (a == b || b == c || a == c)) return;
    out.insert(out.end(), {base + static_cast<std::int32_t>(a), base + static_cast<std::int32_t>(b), base + static_cast<std::int32_t>(c)});
  };
  if (mode == kTriangles) {
    if (n % 3 != 0) throw Problem(where, "its " + text(n) + " vertex indices are not a whole number of triangles");
    out.reserve(out.size() + n);
    for (std::size_t i = 0; i < n; i += 3) put(v[i], v[i + 1], v[i + 2], true);
    return;
  }
  if (n < 3) throw Problem(where, "a triangle " + std::string(mode == kTriangleStrip ? "strip" : "fan") + " of " + text(n) + " vertices");
  for (std::size_t i = 0; i + 2 < n; ++i) {
    if (mode == kTriangleStrip) put(v[i], v[i + 1 + i % 2], v[i + 2 - i % 2], false);
    else put(v[i + 1], v[i + 2], v[0], false);
  }
}

// Triangles a primitive of `indices` vertex indices makes at most.
std::uint64_t triangles_of(std::uint64_t mode, std::uint64_t indices) {
  if (mode == kTriangles) return indices / 3;
  return indices >= 2 ? indices - 2 : 0;
}

// Whether the primitive's positions and indices come from its Draco data: always where this
// build decodes Draco, else only where the file has no uncompressed copy (then refused).
bool draco_decoded(Document& doc, const Primitive& p) {
  if (!p.draco) return false;
  const bool uncompressed_copy = doc.accessor(p.position).view && (!p.indices || doc.accessor(*p.indices).view);
  return draco_supported() || !uncompressed_copy;
}

// What a primitive's vertices are: its POSITION accessor and its targets' (-1: none). Exporters
// write a mesh of several materials as primitives that share these; they share their vertices
// here too. Draco primitives have vertices of their own.
std::optional<std::vector<long long>> vertex_source(Document& doc, const Primitive& p) {
  if (draco_decoded(doc, p)) return std::nullopt;
  std::vector<long long> key{static_cast<long long>(p.position)};
  for (std::size_t t = 0; t < p.target_count(); ++t) {
    const Object target((*p.targets)[t], p.where + ".targets[" + text(t) + "]");
    const auto accessor = target.optional_index("POSITION", doc.count("accessors"), "accessors");
    key.push_back(accessor ? static_cast<long long>(*accessor) : -1);
  }
  return key;
}

// The vertices the primitives have, those they share counted once; at most 2^53 each, and the
// sum stops past `bound`.
std::uint64_t distinct_vertices(Document& doc, const std::vector<Primitive>& primitives, std::uint64_t bound) {
  std::set<std::vector<long long>> seen;
  std::uint64_t total = 0;
  for (const Primitive& p : primitives) {
    const auto source = vertex_source(doc, p);
    if (source && !seen.insert(*source).second) continue;
    total += doc.accessor(p.position).count;
    if (total > bound) break;
  }
  return total;
}

// A primitive's vertex indices: its indices accessor's, or 0 to n - 1 without one.
std::vector<std::uint32_t> read_indices(AccessorReader& reader, const Primitive& p, std::uint64_t n) {
  if (p.indices) return reader.indices(*p.indices, "indices of " + p.where);
  reader.budget().take(4 * n, p.where);
  std::vector<std::uint32_t> indices(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<std::uint32_t>(i);
  return indices;
}

struct Geometry {
  std::vector<float> positions;
  std::vector<std::uint32_t> indices;
  std::uint64_t mode = kTriangles;
};

// What libdraco's decoder holds while it decodes, per declared vertex (attribute values, their
// quantised and predicted copies, the point map) and face (the corner table and traversal),
// with margin: counted against the decode budget before it runs.
constexpr std::uint64_t kDracoTableBytesPerVertex = 96, kDracoTableBytesPerFace = 64;

Geometry read_draco(AccessorReader& reader, const Primitive& p, const ImportLimits& limits) {
  Document& doc = reader.document();
  const Accessor& position = doc.accessor(p.position);
  const Object& ext = *p.draco;
  const std::size_t view = ext.index("bufferView", doc.count("bufferViews"), "bufferViews");
  const std::uint64_t id = ext.object("attributes").size("POSITION");
  if (id > 0xFFFFFFFFu) ext.fail("attributes.POSITION " + text(id) + " is not a Draco attribute id");
  if (!draco_supported())
    throw Problem(p.where, "this build cannot decode KHR_draco_mesh_compression (it was built without Draco), "
                           "and the primitive has no uncompressed copy");
  const std::string_view stream = reader.data().view(view);
  // libdraco sizes its tables by the counts its stream declares as soon as it reads them:
  // those may not exceed what the accessors (already within the budget) say the mesh is.
  const DracoCounts declared = read_draco_counts(stream, ext.where());
  const std::uint64_t max_faces = p.indices ? doc.accessor(*p.indices).count / 3 : limits.max_triangles;
  if (declared.vertices > position.count)
    throw Problem(ext.where(), "its Draco stream declares " + text(declared.vertices) + " vertices, more than its POSITION accessor's " +
                                   text(position.count));
  if (declared.faces > max_faces)
    throw Problem(ext.where(), "its Draco stream declares " + text(declared.faces) + " faces, more than the " + text(max_faces) +
                                   (p.indices ? " its indices accessor holds" : " an avatar may have"));
  reader.budget().take(kDracoTableBytesPerVertex * declared.vertices + kDracoTableBytesPerFace * declared.faces, ext.where());
  DracoPrimitive d = decode_draco(stream, static_cast<std::uint32_t>(id), position.count, max_faces, ext.where());
  reader.budget().take(4 * (d.positions.size() + d.indices.size()), ext.where());
  if (d.positions.size() / 3 != position.count)
    throw Problem(p.where, "its Draco mesh has " + text(d.positions.size() / 3) + " points, its POSITION accessor " +
                               text(position.count));
  if (p.indices && doc.accessor(*p.indices).count != d.indices.size())
    throw Problem(p.where, "its Draco mesh has " + text(d.indices.size()) + " face corners, its indices accessor " +
                               text(doc.accessor(*p.indices).count));
  Geometry g;
  g.positions = std::move(d.positions);
  g.indices = std::move(d.indices);
  g.mode = kTriangles;  // Draco decodes every mode to a triangle list
  return g;
}
}  // namespace

std::uint64_t declared_vertices(Document& doc, std::size_t index) {
  return distinct_vertices(doc, triangle_primitives(doc, doc.item("meshes", index)), kMaxExactInteger);
}

MeshData read_mesh(AccessorReader& reader, std::size_t index, const ImportLimits& limits) {
  Document& doc = reader.document();
  const Object mesh = doc.item("meshes", index);
  MeshData out;
  out.name = mesh.string_or("name", "");
  out.label = label_of(out.name, index);
  const std::vector<Primitive> primitives = triangle_primitives(doc, mesh);

  // Everything the JSON states is checked before anything is decoded. Each count is at most
  // 2^53 and each sum is checked as it grows: no sum wraps.
  const std::uint64_t vertices = distinct_vertices(doc, primitives, limits.max_vertices);
  if (vertices > limits.max_vertices)
    throw Problem(out.label, (primitives.size() == 1 ? text(vertices) : "over " + text(limits.max_vertices)) + " vertices, more than the " +
                                 text(limits.max_vertices) + " an avatar may have");
  std::uint64_t triangles = 0;
  for (const Primitive& p : primitives) {
    triangles += triangles_of(p.mode, p.indices ? doc.accessor(*p.indices).count : doc.accessor(p.position).count);
    if (triangles > limits.max_triangles)
      throw Problem(out.label, "over " + text(limits.max_triangles) + " triangles, more than an avatar may have");
  }
  const std::size_t targets = primitives.empty() ? 0 : primitives[0].target_count();
  for (const Primitive& p : primitives)
    if (p.target_count() != targets)
      throw Problem(out.label, "primitive " + text(p.number) + " has " + text(p.target_count()) + " morph targets, primitive " +
                                   text(primitives[0].number) + " " + text(targets) + " (a mesh's primitives share their targets)");
  if (targets > limits.max_morph_targets)
    throw Problem(out.label, text(targets) + " morph targets, more than the " + text(limits.max_morph_targets) + " a mesh may have");
  const std::vector<std::string> names = target_names(mesh, primitives, targets);
  out.shapes.resize(targets);
  for (std::size_t t = 0; t < targets; ++t) out.shapes[t].name = names[t];

  struct Placed {
    std::int32_t base;
    std::uint64_t count;
  };
  std::map<std::vector<long long>, Placed> placed;  // vertex data already in the mesh
  for (const Primitive& p : primitives) {
    const std::string primitive = out.label + " primitive " + text(p.number);
    const auto source = vertex_source(doc, p);
    const auto shared = source ? placed.find(*source) : placed.end();
    Geometry g;
    Placed at{static_cast<std::int32_t>(out.vertices.size() / 3), 0};
    if (shared != placed.end()) {
      at = shared->second;
      g.mode = p.mode;
      g.indices = read_indices(reader, p, at.count);
    } else if (!source) {
      g = read_draco(reader, p, limits);
      at.count = g.positions.size() / 3;
    } else {
      g.mode = p.mode;
      g.positions = reader.floats(p.position, "VEC3", false, "POSITION of " + p.where);
      at.count = g.positions.size() / 3;
      g.indices = read_indices(reader, p, at.count);
      placed.emplace(*source, at);
    }
    for (std::size_t i = 0; i < g.indices.size(); ++i)
      if (g.indices[i] >= at.count)
        throw Problem(primitive, "its vertex index " + text(g.indices[i]) + " (number " + text(i) + ") is not below its " + text(at.count) +
                                     " vertices");
    append_triangles(g.mode, g.indices, at.base, out.triangles, primitive);
    if (g.positions.empty()) continue;  // shared: its vertices and their deltas are in already
    out.vertices.insert(out.vertices.end(), g.positions.begin(), g.positions.end());
    for (std::size_t t = 0; t < targets; ++t) {
      const Object target((*p.targets)[t], p.where + ".targets[" + text(t) + "]");
      const std::optional<std::size_t> accessor = target.optional_index("POSITION", doc.count("accessors"), "accessors");
      std::vector<float> deltas;
      if (accessor) {
        deltas = reader.floats(*accessor, "VEC3", false, "morph target " + text(t) + " of " + p.where);
      } else {  // a target of normals alone: its positions do not move
        reader.budget().take(4 * g.positions.size(), target.where());
        deltas.assign(g.positions.size(), 0.0f);
      }
      if (deltas.size() != g.positions.size())
        throw Problem(primitives.size() == 1 ? out.label : primitive,
                      "shape '" + names[t] + "' has " + text(deltas.size() / 3) + " vertices, the " +
                          (primitives.size() == 1 ? "mesh " : "primitive ") + text(at.count));
      std::vector<float>& joined = out.shapes[t].deltas;
      if (joined.empty()) joined = std::move(deltas);
      else joined.insert(joined.end(), deltas.begin(), deltas.end());
    }
  }
  if (out.triangles.size() / 3 > limits.max_triangles)
    throw Problem(out.label, text(out.triangles.size() / 3) + " triangles, more than the " + text(limits.max_triangles) +
                                 " an avatar may have");
  return out;
}

}  // namespace softdeca::avatar_import::gltf
