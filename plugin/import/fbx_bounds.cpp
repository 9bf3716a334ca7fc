// The FBX structure scan before assimp (fbx_bounds.h).
// Kept whole: the binary and the ASCII walk share the budgets, the object graph and its checks;
// apart, each would need the other's state.
#include "fbx_bounds.h"

#if SOFTDECA_HAVE_ZLIB
#include <zlib.h>
#endif

#include <cstdio>
#include <algorithm>
#include <cstring>
#include <functional>
#include <unordered_map>
#include <limits>
#include <stdexcept>
#include <vector>

namespace softdeca::avatar_import {

namespace {
constexpr char kBinaryMagic[] = "Kaydara FBX Binary  ";  // then NUL, 0x1A, NUL and the version
constexpr std::size_t kBinaryHeader = 27;

// "1.5 GiB", "640 MiB", "12 KiB", "900 bytes".
std::string size_text(std::uint64_t bytes) {
  const char* units[] = {"KiB", "MiB", "GiB", "TiB"};
  if (bytes < 1024) return std::to_string(bytes) + " bytes";
  double v = static_cast<double>(bytes) / 1024;
  int u = 0;
  while (v >= 1024 && u < 3) v /= 1024, ++u;
  char text[32];
  std::snprintf(text, sizeof text, "%.3g %s", v, units[u]);
  return text;
}

// The error messages: "<path>: <what>"; a structure that is not FBX's, "<path>: not a readable
// FBX file: <what>".
struct Refuse {
  const std::string& path;
  [[noreturn]] void operator()(const std::string& what) const { throw std::runtime_error(path + ": " + what); }
  [[noreturn]] void broken(const std::string& what) const { operator()("not a readable FBX file: " + what); }
};

// "the 1 GiB an avatar may decode", or the file's own budget when it is the smaller.
std::string budget_text(std::uint64_t budget, std::uint64_t file_bytes, const ImportLimits& limits, const char* what) {
  if (budget >= limits.max_decoded_bytes) return "the " + size_text(budget) + " an avatar may decode";
  return "the " + size_text(budget) + " a file of " + size_text(file_bytes) + " may " + what;
}

// What all the file's tokens and arrays cost the reader, against its budgets.
struct Budget {
  const ImportLimits& limits;
  const Refuse& refuse;
  std::uint64_t file_bytes = 0;
  std::uint64_t decoded_budget = fbx_decoded_budget(file_bytes, limits), token_budget = fbx_token_budget(file_bytes, limits);
  std::uint64_t values = 0, decoded = 0;

  void add_values(std::uint64_t n, const char* kind) {
    values += n;
    if (values > token_budget / kFbxBytesPerToken)
      refuse(std::string(kind) + " FBX of more than " + std::to_string(values) + " values: the reader would hold more than " +
             budget_text(token_budget, file_bytes, limits, "hold") + " (about " + std::to_string(kFbxBytesPerToken) +
             " bytes a value)");
  }
  // `where` (a callable) names the array, only when it is refused.
  template <class Where>
  void add_array(std::uint64_t bytes, const Where& where) {
    if (bytes > decoded_budget)
      refuse(where() + ": an array that would expand to " + size_text(bytes) + ", more than " +
             budget_text(decoded_budget, file_bytes, limits, "expand to"));
    decoded += bytes;
    if (decoded > decoded_budget)
      refuse("its arrays would expand to more than " + budget_text(decoded_budget, file_bytes, limits, "expand to") + " (" +
             size_text(decoded) + " by " + where() + ")");
  }
};

// ---- the objects and their connections ------------------------------------------------------

// What assimp makes of the objects once it has parsed them, bounded before it does: it follows
// connections by recursion (a chain of 10,000 bones overflows its stack), makes a scene node of
// a Model once per path from the root (a ladder of 30 pairs makes a billion); and per blend shape
// of a mesh, a copy of the mesh's per-corner vertices and normals (a thousand tiny shapes on a
// mesh of ten million corners make a quarter of a terabyte).
struct SceneGraph {
  std::vector<std::int64_t> models, shapes, channels, blend_shapes;  // ids by class
  std::unordered_map<std::int64_t, std::pair<std::string, std::uint64_t>> meshes;  // id -> name, corners
  std::vector<std::pair<std::int64_t, std::int64_t>> links;  // object-object connections (child, parent)

  // An object of `kind` (Model, Geometry, Deformer) and `cls` (its class: Mesh, Shape, ...).
  void object(const std::string& kind, std::int64_t id, const std::string& cls, const std::string& name) {
    if (kind == "Model") models.push_back(id);
    if (kind == "Geometry" && cls == "Mesh") meshes[id] = {name, 0};
    if (kind == "Geometry" && cls == "Shape") shapes.push_back(id);
    if (kind == "Deformer" && cls == "BlendShapeChannel") channels.push_back(id);
    if (kind == "Deformer" && cls == "BlendShape") blend_shapes.push_back(id);
  }
};

// An object's name as FBX stores it ("Head\0\1Geometry" in binary, "Geometry::Head" in ASCII).
std::string object_name(const std::string& stored) {
  const std::size_t nul = stored.find('\0');
  if (nul != std::string::npos) return stored.substr(0, nul);
  const std::size_t colons = stored.find("::");
  return colons == std::string::npos ? stored : stored.substr(colons + 2);
}

// The chains of object-object connections: at most max_node_depth long, without a cycle; the
// Model objects' scene nodes (one per path from the root) at most max_nodes. Returns the
// longest chain.
std::size_t check_connections(const SceneGraph& g, const Refuse& refuse, const ImportLimits& limits) {
  std::unordered_map<std::int64_t, std::size_t> index;  // object id -> its place; the root (0) first
  index.reserve(2 * g.links.size() + 1);
  index.emplace(0, 0);
  for (const auto& [child, parent] : g.links) index.emplace(parent, index.size()), index.emplace(child, index.size());
  const std::size_t n = index.size();
  std::vector<uint8_t> model(n, 0);
  for (const std::int64_t id : g.models)
    if (const auto m = index.find(id); m != index.end() && m->second != 0) model[m->second] = 1;
  std::vector<std::vector<std::size_t>> children(n);
  std::vector<std::size_t> waiting(n, 0);
  for (const auto& [child, parent] : g.links) {
    const std::size_t c = index[child];
    children[index[parent]].push_back(c);
    ++waiting[c];
  }
  // In topological order: the longest chain to each object, and for models the paths to it
  // from the root through models (the scene nodes made of it).
  std::vector<std::uint64_t> depth(n, 0), paths(n, 0);
  paths[0] = 1;
  std::vector<std::size_t> ready;
  for (std::size_t i = 0; i < n; ++i)
    if (!waiting[i]) ready.push_back(i);
  std::size_t done = 0, deepest = 0;
  std::uint64_t nodes = 0;
  while (!ready.empty()) {
    const std::size_t m = ready.back();
    ready.pop_back();
    ++done;
    nodes += paths[m];
    deepest = std::max<std::size_t>(deepest, depth[m]);
    if (nodes > limits.max_nodes)
      refuse("its models make more than " + std::to_string(limits.max_nodes) +
             " scene nodes (a model connected to many parents makes a node for each path to it)");
    if (depth[m] > static_cast<std::uint64_t>(limits.max_node_depth))
      refuse("objects connected more than " + std::to_string(limits.max_node_depth) + " deep");
    for (const std::size_t c : children[m]) {
      depth[c] = std::max(depth[c], depth[m] + 1);
      if (model[c]) paths[c] = std::min<std::uint64_t>(paths[c] + paths[m], std::uint64_t{1} << 62);
      if (--waiting[c] == 0) ready.push_back(c);
    }
  }
  if (done != n) refuse("objects connected in a cycle");
  return deepest;
}

// Per mesh, the shapes assimp copies it for: each link of a shape to a channel of a blend
// shape deformer of the mesh, counted (saturating) over every path.
void check_blend_shapes(const SceneGraph& g, const Refuse& refuse, const ImportLimits& limits) {
  constexpr std::uint64_t kCap = std::uint64_t{1} << 40;
  const auto counted = [](const std::vector<std::int64_t>& ids) {
    std::unordered_map<std::int64_t, std::uint64_t> m;
    for (const std::int64_t id : ids) m.emplace(id, 0);
    return m;
  };
  std::unordered_map<std::int64_t, std::uint64_t> shapes = counted(g.shapes), per_channel = counted(g.channels),
                                                  per_blend = counted(g.blend_shapes);
  const auto add = [&](std::unordered_map<std::int64_t, std::uint64_t>& into, const std::unordered_map<std::int64_t, std::uint64_t>& from,
                       bool one) {
    for (const auto& [child, parent] : g.links) {
      const auto c = from.find(child);
      const auto p = into.find(parent);
      if (c != from.end() && p != into.end()) p->second = std::min(kCap, p->second + (one ? 1 : c->second));
    }
  };
  add(per_channel, shapes, true);
  add(per_blend, per_channel, false);
  std::unordered_map<std::int64_t, std::uint64_t> per_mesh;
  for (const auto& [id, mesh] : g.meshes) per_mesh.emplace(id, 0);
  add(per_mesh, per_blend, false);
  // What the reader holds per polygon corner: the mesh's own (positions, normals, texture
  // coordinates, 48 bytes) and, per shape, positions and normals (24).
  std::uint64_t total = 0;
  for (const auto& [id, mesh] : g.meshes) {
    const std::uint64_t corners = mesh.second, copies = per_mesh[id];
    const double bytes = static_cast<double>(corners) * (48.0 + 24.0 * static_cast<double>(copies));
    total += static_cast<std::uint64_t>(std::min(bytes, 1e18));
    if (total > limits.max_decoded_bytes)
      refuse("mesh '" + mesh.first + "': its " + std::to_string(copies) + " blend shapes over " + std::to_string(corners) +
             " polygon corners would take the reader " + size_text(static_cast<std::uint64_t>(std::min(bytes, 1e18))) +
             " (a copy of the corners for each), more than the " + size_text(limits.max_decoded_bytes) +
             " an avatar may decode");
  }
}

std::size_t check_scene_graph(const SceneGraph& g, const Refuse& refuse, const ImportLimits& limits) {
  const std::size_t depth = check_connections(g, refuse, limits);
  check_blend_shapes(g, refuse, limits);
  return depth;
}

// ---- binary FBX ---------------------------------------------------------------------------

// Little-endian reads at checked offsets.
struct Bytes {
  const unsigned char* data;
  std::uint64_t size;
  std::uint64_t u32(std::uint64_t at) const {
    std::uint32_t v;
    std::memcpy(&v, data + at, 4);
    return v;
  }
  std::uint64_t u64(std::uint64_t at) const {
    std::uint64_t v;
    std::memcpy(&v, data + at, 8);
    return v;
  }
  std::int32_t i32(std::uint64_t at) const {
    std::int32_t v;
    std::memcpy(&v, data + at, 4);
    return v;
  }
};

#if SOFTDECA_HAVE_ZLIB
// Decompresses the zlib stream in[0, n) to exactly `size` bytes, handing them to `take` in
// pieces; false when the stream is damaged, ends early or holds more.
bool inflate_exactly(const unsigned char* in, std::uint64_t n, std::uint64_t size,
                     const std::function<void(const unsigned char*, std::size_t)>& take) {
  z_stream z{};
  if (inflateInit(&z) != Z_OK) return false;
  z.next_in = const_cast<unsigned char*>(in);
  z.avail_in = static_cast<uInt>(n);
  unsigned char out[1 << 16];
  std::uint64_t total = 0;
  int status = Z_OK;
  while (status == Z_OK) {
    z.next_out = out;
    z.avail_out = sizeof out;
    status = inflate(&z, Z_NO_FLUSH);  // Z_BUF_ERROR: no progress, the stream cut short
    const std::size_t got = sizeof out - z.avail_out;
    total += got;
    if (total > size) break;
    if (got && take) take(out, got);
  }
  inflateEnd(&z);
  return status == Z_STREAM_END && total == size;
}
#else
// Without zlib a stream is taken at the size it declares: a build without zlib has no assimp to
// hand it to either.
bool inflate_exactly(const unsigned char*, std::uint64_t, std::uint64_t, const std::function<void(const unsigned char*, std::size_t)>&) {
  return true;
}
#endif

// The int32 values of an array's bytes, however they arrive in pieces.
struct Int32Reader {
  std::function<void(std::int32_t)> each;
  unsigned char carry[4];
  int held = 0;
  void operator()(const unsigned char* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      carry[held++] = p[i];
      if (held == 4) {
        std::int32_t v;
        std::memcpy(&v, carry, 4);
        each(v);
        held = 0;
      }
    }
  }
};

// A node being read: where its children end (then the empty record) and where it ends; for a
// Geometry object, what its arrays add up to.
struct Open {
  std::string name;
  std::uint64_t children_end = 0, end = 0;
  enum class Geometry { none, mesh, shape } geometry = Geometry::none;
  std::uint64_t coordinates = 0, indexes = 0;  // Vertices' and a shape's Indexes' lengths
  bool has_coordinates = false, has_indexes = false;
  std::int64_t top_index = -1;  // the largest vertex a polygon names
  std::int64_t id = 0;          // an object's
};

class BinaryWalk {
 public:
  BinaryWalk(const Bytes& b, const Refuse& refuse, const ImportLimits& limits)
      : b_(b), refuse_(refuse), limits_(limits), budget_{limits, refuse, b.size} {}

  FbxScan run() {
    if (b_.size < kBinaryHeader) refuse_.broken("a binary FBX header cut short");
    const std::uint64_t version = b_.u32(23);
    FbxScan s;
    s.binary = true;
    s.version = static_cast<std::uint32_t>(version);
    wide_ = version >= 7500;
    const std::uint64_t header = wide_ ? 25 : 13;  // of a node record, and the empty record
    std::uint64_t pos = kBinaryHeader;
    for (;;) {
      if (!open_.empty() && pos == open_.back().children_end) {
        if (pos + header > b_.size || !zeros(pos, header)) refuse_.broken(where() + ": its children do not end with an empty record");
        pos += header;
        close();
        continue;
      }
      const std::uint64_t limit = open_.empty() ? b_.size : open_.back().children_end;
      if (open_.empty() && pos == b_.size) break;  // the top level ends with the file
      if (pos + header > limit) {
        if (open_.empty()) refuse_.broken("it ends inside a node record (truncated?)");
        refuse_.broken(where() + ": a child node runs past the end of its parent");
      }
      const std::uint64_t end = wide_ ? b_.u64(pos) : b_.u32(pos);
      const std::uint64_t count = wide_ ? b_.u64(pos + 8) : b_.u32(pos + 4);
      const std::uint64_t length = wide_ ? b_.u64(pos + 16) : b_.u32(pos + 8);
      const std::uint64_t name_length = b_.data[pos + header - 1];
      if (end == 0) {
        if (open_.empty()) break;  // the top level's end; a footer follows
        refuse_.broken(at(pos) + ": a node without an end");
      }
      if (end <= pos || end > limit) refuse_.broken(at(pos) + ": its end lies outside " + (open_.empty() ? "the file" : "its parent"));
      const std::uint64_t name_at = pos + header, first = name_at + name_length;
      if (first > end) refuse_.broken(at(pos) + ": its name runs past its end");
      Open node;
      node.name.assign(reinterpret_cast<const char*>(b_.data + name_at), name_length);
      if (length > end - first) refuse_.broken(where(node.name) + ": its properties run past its end");
      const std::uint64_t last = first + length;
      if (count > length / 2) refuse_.broken(where(node.name) + ": " + std::to_string(count) + " properties in " + std::to_string(length) + " bytes");
      budget_.add_values(1 + 2 * count, "a binary");  // its name, each property and a separator
      const Firsts firsts = properties(node, first, last, count);
      const std::string& kind = firsts.last_string;
      if (node.name == "Geometry") {
        node.geometry = kind == "Mesh" ? Open::Geometry::mesh : kind == "Shape" ? Open::Geometry::shape : Open::Geometry::none;
        meshes_ += node.geometry == Open::Geometry::mesh;
      }
      const bool top_child = open_.size() == 1;
      if (top_child && open_[0].name == "Objects" && count > 0) {
        node.id = firsts.number[0];
        graph_.object(node.name, node.id, kind, object_name(firsts.text[1]));
      }
      if (top_child && open_[0].name == "Connections" && node.name == "C" && count >= 3 && firsts.text[0] == "OO")
        graph_.links.emplace_back(firsts.number[1], firsts.number[2]);
      pos = last;
      if (pos == end) {
        finish(node);
        continue;
      }
      if (end - pos < header) refuse_.broken(where(node.name) + ": its children do not fit before its end");
      if (static_cast<int>(open_.size()) >= limits_.max_fbx_depth)
        refuse_("nested more than " + std::to_string(limits_.max_fbx_depth) + " deep (at byte " + std::to_string(pos) + ")");
      node.children_end = end - header;
      node.end = end;
      open_.push_back(std::move(node));
      deepest_ = std::max(deepest_, static_cast<int>(open_.size()));
      budget_.add_values(2, "a binary");  // the braces of its children
    }
    s.connection_depth = check_scene_graph(graph_, refuse_, limits_);
    s.depth = deepest_;
    s.meshes = meshes_;
    s.values = budget_.values;
    s.decoded_bytes = budget_.decoded;
    return s;
  }

 private:
  bool zeros(std::uint64_t at, std::uint64_t n) const {
    for (std::uint64_t i = 0; i < n; ++i)
      if (b_.data[at + i]) return false;
    return true;
  }

  // "node 'Objects/Geometry/Vertices'": the nodes open, then `name`.
  std::string where(const std::string& name = "") const {
    std::string w;
    for (const Open& o : open_) w += (w.empty() ? "" : "/") + o.name;
    if (!name.empty()) w += (w.empty() ? "" : "/") + name;
    return "node '" + w + "'";
  }
  // A node not yet named: "the node at byte 123", "node 'Objects': the child at byte 123".
  std::string at(std::uint64_t pos) const {
    const std::string here = "the node at byte " + std::to_string(pos);
    return open_.empty() ? here : where() + ": " + here.substr(4);
  }

  // A node's first properties, as far as the walk needs them: ids, a connection's type, a
  // Geometry's class (its last short string).
  struct Firsts {
    std::int64_t number[3] = {0, 0, 0};
    std::string text[3];
    std::string last_string;
  };

  // Reads `count` properties in [at, last) exactly.
  Firsts properties(Open& node, std::uint64_t at, std::uint64_t last, std::uint64_t count) {
    Firsts firsts;
    std::string& last_string = firsts.last_string;
    for (std::uint64_t i = 0; i < count; ++i) {
      if (at >= last) refuse_.broken(where(node.name) + ": its properties run past their length");
      const char type = static_cast<char>(b_.data[at++]);
      const auto need = [&](std::uint64_t n) {
        if (n > last - at) refuse_.broken(where(node.name) + ": a property of type '" + std::string(1, type) + "' runs past its node");
      };
      switch (type) {
        case 'C': need(1), at += 1; break;
        case 'Y': need(2), at += 2; break;
        case 'I': case 'F': need(4), at += 4; break;
        case 'D': case 'L':
          need(8);
          if (type == 'L' && i < 3) std::memcpy(&firsts.number[i], b_.data + at, 8);
          at += 8;
          break;
        case 'S': case 'R': {
          need(4);
          const std::uint64_t n = b_.u32(at);
          at += 4;
          need(n);
          if (type == 'S' && n <= 64) last_string.assign(reinterpret_cast<const char*>(b_.data + at), n);
          if (type == 'S' && n <= 64 && i < 3) firsts.text[i] = last_string;
          at += n;
          break;
        }
        case 'f': case 'd': case 'l': case 'i': case 'b': case 'c': at = array(node, type, at, last); break;
        default: refuse_.broken(where(node.name) + ": a property of unknown type (byte " + std::to_string(at - 1) + ")");
      }
    }
    if (at != last) refuse_.broken(where(node.name) + ": its properties do not fill their declared length");
    return firsts;
  }

  std::uint64_t array(Open& node, char type, std::uint64_t at, std::uint64_t last) {
    const auto here = [&] { return where(node.name); };
    if (12 > last - at) refuse_.broken(here() + ": an array's header runs past its node");
    const std::uint64_t length = b_.u32(at), encoding = b_.u32(at + 4), stored = b_.u32(at + 8);
    at += 12;
    if (stored > last - at) refuse_.broken(here() + ": an array's data runs past its node");
    const std::uint64_t element = type == 'd' || type == 'l' ? 8 : type == 'f' || type == 'i' ? 4 : 1;
    const std::uint64_t bytes = length * element;  // at most 2^35: no overflow
    budget_.add_array(bytes, here);
    // The reader sizes its buffer in 32 bits.
    if (bytes > std::numeric_limits<std::uint32_t>::max()) refuse_(here() + ": an array of " + size_text(bytes));
    Open* geometry = open_.empty() ? nullptr : &open_.back();
    if (geometry && geometry->geometry == Open::Geometry::none) geometry = nullptr;
    std::function<void(const unsigned char*, std::size_t)> take;
    Int32Reader ints;
    if (geometry && node.name == "Vertices") geometry->coordinates = length, geometry->has_coordinates = true;
    if (geometry && node.name == "Indexes") geometry->indexes = length, geometry->has_indexes = true;
    if (geometry && geometry->geometry == Open::Geometry::mesh && node.name == "PolygonVertexIndex")
      graph_.meshes[geometry->id].second = length;
    if (geometry && geometry->geometry == Open::Geometry::mesh && node.name == "PolygonVertexIndex" && type == 'i') {
      ints.each = [geometry](std::int32_t v) {
        const std::int64_t vertex = v < 0 ? ~static_cast<std::int64_t>(v) : v;  // a polygon's last corner is stored negated
        geometry->top_index = std::max(geometry->top_index, vertex);
      };
      take = std::ref(ints);
    }
    if (encoding == 0) {
      if (stored != bytes)
        refuse_.broken(here() + ": an array of " + std::to_string(length) + " elements that holds " + std::to_string(stored) + " bytes");
      if (take) take(b_.data + at, static_cast<std::size_t>(stored));
    } else if (encoding == 1) {
      if (!inflate_exactly(b_.data + at, stored, bytes, take))
        refuse_.broken(here() + ": an array whose compressed data is damaged or not the " + size_text(bytes) + " it declares");
    } else {
      refuse_.broken(here() + ": an array of unknown encoding " + std::to_string(encoding));
    }
    return at + stored;
  }

  // A node read to its end: a Geometry's arrays must add up.
  void finish(const Open& node) {
    if (node.geometry == Open::Geometry::mesh) {
      if (node.coordinates % 3)
        refuse_.broken(where(node.name) + ": a mesh's Vertices hold " + std::to_string(node.coordinates) + " numbers, not a multiple of 3");
      if (node.top_index >= static_cast<std::int64_t>(node.coordinates / 3))
        refuse_.broken(where(node.name) + ": a polygon names vertex " + std::to_string(node.top_index) + " of a mesh of " +
                std::to_string(node.coordinates / 3));
    }
    if (node.geometry == Open::Geometry::shape && node.has_indexes && node.has_coordinates && node.indexes * 3 != node.coordinates)
      refuse_.broken(where(node.name) + ": a blend shape of " + std::to_string(node.indexes) + " indexes and " +
              std::to_string(node.coordinates) + " numbers (3 per index)");
  }

  void close() {
    const Open node = std::move(open_.back());
    open_.pop_back();
    finish(node);
  }

  const Bytes& b_;
  const Refuse& refuse_;
  const ImportLimits& limits_;
  Budget budget_;
  bool wide_ = false;
  std::vector<Open> open_;
  std::size_t meshes_ = 0;
  int deepest_ = 0;
  SceneGraph graph_;
};

// ---- ASCII FBX ----------------------------------------------------------------------------

// Text: "Key: value, value {" lines; ';' starts a comment, '"' a string.
class AsciiWalk {
 public:
  AsciiWalk(const std::string& text, const Refuse& refuse, const ImportLimits& limits)
      : text_(text), refuse_(refuse), limits_(limits), budget_{limits, refuse, text.size()} {}

  FbxScan run() {
    std::size_t token = std::string::npos;  // where the token being read began
    for (std::size_t i = 0; i < text_.size(); ++i) {
      const char c = text_[i];
      const bool separator = c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',' || c == '{' || c == '}' || c == ':' ||
                             c == ';' || c == '"';
      if (!separator) {
        if (token == std::string::npos) token = i;
        continue;
      }
      if (token != std::string::npos) {
        ended(token, i, false, c == ':');
        token = std::string::npos;
      }
      if (c == '\n') ++line_;
      if (c == ';') {  // a comment, to the line's end
        while (i + 1 < text_.size() && text_[i + 1] != '\n' && text_[i + 1] != '\r') ++i;
      } else if (c == '"') {  // a string, one value
        const std::size_t close = text_.find('"', i + 1);
        if (close == std::string::npos) refuse_.broken("line " + std::to_string(line_) + ": a string that never ends");
        for (std::size_t k = i + 1; k < close; ++k) line_ += text_[k] == '\n';
        ended(i + 1, close, true, false);
        i = close;
      } else if (c == ',' || c == '{' || c == '}') {
        ++values_;
        if (c == '{') {
          deepest_ = std::max(deepest_, depth_ + 1);
          if (++depth_ > limits_.max_fbx_depth)
            refuse_("nested more than " + std::to_string(limits_.max_fbx_depth) + " deep (line " + std::to_string(line_) + ")");
          if (depth_ == 1) block_ = key_;
        }
        if (c == '}') --depth_;
      }
      if (values_ >= (1u << 16)) count_values();
    }
    if (token != std::string::npos) ended(token, text_.size(), false, false);
    count_values();
    FbxScan s;
    s.connection_depth = check_scene_graph(graph_, refuse_, limits_);
    s.depth = deepest_;
    s.meshes = graph_.meshes.size();
    s.values = budget_.values;
    s.decoded_bytes = budget_.decoded;
    return s;
  }

 private:
  void count_values() {
    budget_.add_values(values_, "an ASCII");
    values_ = 0;
  }

  // A token [begin, end): a key ("Model" of "Model:"), a string's text or a value.
  void ended(std::size_t begin, std::size_t end, bool string, bool key) {
    ++values_;
    if (key) {
      if (depth_ <= 1) key_.assign(text_, begin, end - begin), field_ = 0;
      if (depth_ == 2) inner_key_.assign(text_, begin, end - begin);
      return;
    }
    // An array's declared count: the reader reserves room for it before reading a value.
    if (!string && text_[begin] == '*') {
      const std::uint64_t declared = std::strtoull(text_.c_str() + begin + 1, nullptr, 10);
      if (declared > (text_.size() - begin) / 2)
        refuse_.broken("line " + std::to_string(line_) + ": an array that declares " + std::to_string(declared) +
                " values, more than the rest of the file can hold");
      budget_.add_array(8 * declared, [&] { return "line " + std::to_string(line_); });
      // A mesh's polygon corners: "PolygonVertexIndex: *N {" inside its Geometry.
      if (depth_ == 2 && inner_key_ == "PolygonVertexIndex" && block_ == "Objects" && key_ == "Geometry" && class_ == "Mesh")
        graph_.meshes[object_id_].second = declared;
    }
    if (depth_ != 1) return;
    // Objects: "Model: id, "Model::name", "class" {"; connections: "C: "OO", child, parent".
    const int field = field_++;
    if (block_ == "Objects") {
      if (field == 0) object_id_ = number(begin), class_.clear(), name_.clear();
      if (field == 1) name_ = object_name(text_.substr(begin, end - begin));
      if (field == 2) {
        class_.assign(text_, begin, end - begin);
        graph_.object(key_, object_id_, class_, name_);
      }
    }
    if (block_ == "Connections" && key_ == "C") {
      if (field == 0) link_type_.assign(text_, begin, end - begin);
      if (field == 1) link_child_ = number(begin);
      if (field == 2 && link_type_ == "OO") graph_.links.emplace_back(link_child_, number(begin));
    }
  }

  std::int64_t number(std::size_t at) const { return std::strtoll(text_.c_str() + at, nullptr, 10); }

  const std::string& text_;
  const Refuse& refuse_;
  const ImportLimits& limits_;
  Budget budget_;
  int depth_ = 0, deepest_ = 0;
  std::uint64_t line_ = 1, values_ = 0;
  std::string key_, block_, inner_key_;  // the last key at the top two levels, and below; the block open
  int field_ = 0;                         // values since that key
  std::string link_type_, class_, name_;  // of the connection, of the object being read
  std::int64_t link_child_ = 0, object_id_ = 0;
  SceneGraph graph_;
};
}  // namespace

std::uint64_t fbx_decoded_budget(std::uint64_t file_bytes, const ImportLimits& limits) {
  return limits.decoded_budget(file_bytes);
}

std::uint64_t fbx_token_budget(std::uint64_t file_bytes, const ImportLimits& limits) {
  return std::min(limits.max_decoded_bytes, 3 * file_bytes + (std::uint64_t{400} << 20));
}

FbxScan scan_fbx(const std::string& bytes, const std::string& path, const ImportLimits& limits) {
  const Refuse refuse{path};
  if (bytes.compare(0, std::strlen(kBinaryMagic), kBinaryMagic) == 0) {
    const Bytes b{reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()};
    return BinaryWalk(b, refuse, limits).run();
  }
  return AsciiWalk(bytes, refuse, limits).run();
}

}  // namespace softdeca::avatar_import
