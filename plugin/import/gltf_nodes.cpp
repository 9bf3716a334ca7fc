#include "gltf_nodes.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "gltf_meshes.h"

namespace softdeca::avatar_import::gltf {

namespace {
using Matrix = Eigen::Matrix4d;
constexpr long long kNone = -1;

std::string text(std::uint64_t n) { return std::to_string(n); }
std::string node_name(std::size_t n) { return "nodes[" + text(n) + "]"; }

struct Node {
  std::string name;
  std::optional<std::size_t> mesh, skin;
  std::vector<std::size_t> children;
  Matrix local = Matrix::Identity();
};

// A column-major 4x4 as glTF stores matrices.
Matrix from_column_major(const double* m) {
  Matrix out;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out(r, c) = m[4 * c + r];
  return out;
}

Node read_node(const Object& o, Document& doc) {
  Node n;
  n.name = o.string_or("name", "");
  n.mesh = o.optional_index("mesh", doc.count("meshes"), "meshes");
  n.skin = o.optional_index("skin", doc.count("skins"), "skins");
  if (const std::vector<Json>* children = o.optional_array("children"))
    for (std::size_t k = 0; k < children->size(); ++k)
      n.children.push_back(as_index((*children)[k], doc.count("nodes"), "nodes", o.at("children") + "[" + text(k) + "]"));
  if (o.has("matrix")) {
    const std::vector<double> m = o.numbers_or("matrix", 16, {});
    n.local = from_column_major(m.data());
  } else {
    const std::vector<double> t = o.numbers_or("translation", 3, {0, 0, 0});
    const std::vector<double> r = o.numbers_or("rotation", 4, {0, 0, 0, 1});
    const std::vector<double> s = o.numbers_or("scale", 3, {1, 1, 1});
    Eigen::Quaterniond q(r[3], r[0], r[1], r[2]);  // glTF stores x, y, z, w
    if (!(q.norm() > 0)) o.fail("rotation [0, 0, 0, 0] is not a rotation");
    q.normalize();
    n.local.topLeftCorner<3, 3>() = q.toRotationMatrix() * Eigen::Vector3d(s[0], s[1], s[2]).asDiagonal();
    n.local.topRightCorner<3, 1>() = Eigen::Vector3d(t[0], t[1], t[2]);
  }
  if (n.mesh)
    if (const auto ext = o.optional_object("extensions"); ext && ext->has("EXT_mesh_gpu_instancing"))
      o.fail("places its mesh with EXT_mesh_gpu_instancing, which this reader does not read");
  return n;
}

class Hierarchy {
 public:
  Hierarchy(Document& doc, const ImportLimits& limits) {
    const std::size_t count = doc.count("nodes");
    if (count > limits.max_nodes)
      throw Problem("", text(count) + " nodes, more than the " + text(limits.max_nodes) + " a file may have");
    nodes_.reserve(count);
    for (std::size_t n = 0; n < count; ++n) nodes_.push_back(read_node(doc.item("nodes", n), doc));
    parent_.assign(count, kNone);
    for (std::size_t n = 0; n < count; ++n)
      for (const std::size_t c : nodes_[n].children) {
        if (c == n) throw Problem(node_name(n), "lists itself among its children");
        if (parent_[c] != kNone)
          throw Problem(node_name(c), "is a child of both " + node_name(static_cast<std::size_t>(parent_[c])) + " and " + node_name(n) +
                                          " (a node has at most one parent)");
        parent_[c] = static_cast<long long>(n);
      }
    place(limits);
  }

  const Node& node(std::size_t n) const { return nodes_[n]; }
  std::size_t size() const { return nodes_.size(); }
  bool is_root(std::size_t n) const { return parent_[n] == kNone; }
  long long parent(std::size_t n) const { return parent_[n]; }
  const Matrix& global(std::size_t n) const { return global_[n]; }

 private:
  // Depths without recursion (each node's path to its root walked once), cycles found on the
  // way; then the global transforms, parents before children.
  void place(const ImportLimits& limits) {
    const std::size_t count = nodes_.size();
    std::vector<long long> depth(count, kNone);
    std::vector<char> on_path(count, 0);
    std::vector<std::size_t> path;
    for (std::size_t n = 0; n < count; ++n) {
      path.clear();
      long long m = static_cast<long long>(n);
      while (m != kNone && depth[static_cast<std::size_t>(m)] == kNone) {
        if (on_path[static_cast<std::size_t>(m)])
          throw Problem(node_name(static_cast<std::size_t>(m)), "is its own ancestor (the node hierarchy has a cycle)");
        on_path[static_cast<std::size_t>(m)] = 1;
        path.push_back(static_cast<std::size_t>(m));
        m = parent_[static_cast<std::size_t>(m)];
      }
      long long d = m == kNone ? -1 : depth[static_cast<std::size_t>(m)];
      for (auto it = path.rbegin(); it != path.rend(); ++it) {
        depth[*it] = ++d;
        on_path[*it] = 0;
        if (d > limits.max_node_depth)
          throw Problem(node_name(*it), "nested " + text(static_cast<std::uint64_t>(d)) + " deep, more than the " +
                                            text(static_cast<std::uint64_t>(limits.max_node_depth)) + " a file may nest its nodes");
      }
    }
    std::vector<std::size_t> order(count);
    for (std::size_t n = 0; n < count; ++n) order[n] = n;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return depth[a] < depth[b]; });
    global_.resize(count);
    for (const std::size_t n : order)
      global_[n] = parent_[n] == kNone ? nodes_[n].local : global_[static_cast<std::size_t>(parent_[n])] * nodes_[n].local;
  }

  std::vector<Node> nodes_;
  std::vector<long long> parent_;
  std::vector<Matrix, Eigen::aligned_allocator<Matrix>> global_;
};

// The scene's root nodes.
std::vector<std::size_t> scene_roots(Document& doc, const Hierarchy& h) {
  std::vector<std::size_t> roots;
  if (doc.count("scenes") == 0) {
    for (std::size_t n = 0; n < h.size(); ++n)
      if (h.is_root(n)) roots.push_back(n);
    return roots;
  }
  const std::size_t s = doc.root().optional_index("scene", doc.count("scenes"), "scenes").value_or(0);
  const Object scene = doc.item("scenes", s);
  const std::vector<Json>* listed = scene.optional_array("nodes");
  if (!listed) return roots;
  std::vector<char> seen(h.size(), 0);
  for (std::size_t k = 0; k < listed->size(); ++k) {
    const std::string where = scene.at("nodes") + "[" + text(k) + "]";
    const std::size_t n = as_index((*listed)[k], h.size(), "nodes", where);
    if (!h.is_root(n)) throw Problem(where, node_name(n) + " is a child of another node, not a root");
    if (seen[n]) throw Problem(where, "lists " + node_name(n) + " a second time");
    seen[n] = 1;
    roots.push_back(n);
  }
  return roots;
}

// Where a skin's joints place its mesh, when they all agree (see the header).
std::optional<Matrix> skin_placement(AccessorReader& reader, std::size_t skin, const Hierarchy& h) {
  Document& doc = reader.document();
  const Object o = doc.item("skins", skin);
  const std::vector<Json>& list = o.array("joints");
  if (list.empty()) o.fail("has no joints");
  std::vector<float> inverse_bind;
  if (const auto accessor = o.optional_index("inverseBindMatrices", doc.count("accessors"), "accessors")) {
    inverse_bind = reader.floats(*accessor, "MAT4", true, "inverseBindMatrices of " + o.where());
    if (inverse_bind.size() / 16 < list.size())
      o.fail("has " + text(list.size()) + " joints but " + text(inverse_bind.size() / 16) + " inverse bind matrices");
  }
  std::optional<Matrix> first;
  for (std::size_t j = 0; j < list.size(); ++j) {
    const std::size_t joint = as_index(list[j], h.size(), "nodes", o.at("joints") + "[" + text(j) + "]");
    Matrix bind = Matrix::Identity();
    if (!inverse_bind.empty()) {
      double m[16];
      for (int k = 0; k < 16; ++k) m[k] = inverse_bind[16 * j + static_cast<std::size_t>(k)];
      bind = from_column_major(m);
    }
    const Matrix placement = h.global(joint) * bind;
    if (!first) {
      first = placement;
      continue;
    }
    // Equal within what float inverse bind matrices hold: relative to the placement's scale
    // for its linear part, and to its scale and offset for its translation.
    const double linear = first->topLeftCorner<3, 3>().cwiseAbs().maxCoeff();
    const double offset = std::max(linear, first->topRightCorner<3, 1>().cwiseAbs().maxCoeff());
    const Matrix d = (placement - *first).cwiseAbs();
    if (!(d.topLeftCorner<3, 3>().maxCoeff() <= 1e-4 * linear) || !(d.topRightCorner<3, 1>().maxCoeff() <= 1e-4 * offset))
      return std::nullopt;
  }
  return first;
}

// The node's name, else its mesh's, else its nearest named ancestor's (optimizers move meshes
// to unnamed child nodes of the named ones).
std::string instance_name(Document& doc, const Hierarchy& h, std::size_t n) {
  if (!h.node(n).name.empty()) return h.node(n).name;
  const std::size_t mesh = *h.node(n).mesh;
  const std::string own = doc.item("meshes", mesh).string_or("name", "");
  if (!own.empty()) return own;
  for (long long a = h.parent(n); a != kNone; a = h.parent(static_cast<std::size_t>(a)))
    if (!h.node(static_cast<std::size_t>(a)).name.empty()) return h.node(static_cast<std::size_t>(a)).name;
  return "meshes[" + text(mesh) + "]";
}
}  // namespace

std::vector<Instance> scene_instances(AccessorReader& reader, const ImportLimits& limits) {
  Document& doc = reader.document();
  const Hierarchy h(doc, limits);
  std::vector<std::size_t> stack = scene_roots(doc, h);
  std::reverse(stack.begin(), stack.end());
  std::vector<std::size_t> with_mesh;
  while (!stack.empty()) {  // depth first, children in order; the hierarchy is a forest
    const std::size_t n = stack.back();
    stack.pop_back();
    if (h.node(n).mesh) with_mesh.push_back(n);
    const std::vector<std::size_t>& children = h.node(n).children;
    stack.insert(stack.end(), children.rbegin(), children.rend());
  }
  // A mesh used by many nodes counts once for each: the bound holds before anything is decoded.
  std::map<std::size_t, std::uint64_t> declared;
  std::uint64_t instanced = 0;
  for (const std::size_t n : with_mesh) {
    const std::size_t mesh = *h.node(n).mesh;
    auto it = declared.find(mesh);
    if (it == declared.end()) it = declared.emplace(mesh, declared_vertices(doc, mesh)).first;
    instanced += it->second;  // each term at most 2^53, and the sum stops at the bound
    if (instanced > limits.max_instanced_vertices)
      throw Problem("", "its scene places more than " + text(limits.max_instanced_vertices) +
                            " vertices (a mesh counts once for every node that uses it), more than an avatar may have");
  }
  std::map<std::size_t, std::optional<Matrix>> skins;
  std::vector<Instance> out;
  for (const std::size_t n : with_mesh) {
    const Node& node = h.node(n);
    Instance instance;
    instance.node = n;
    instance.mesh = *node.mesh;
    instance.name = instance_name(doc, h, n);
    Matrix placement = h.global(n);
    if (node.skin) {
      auto it = skins.find(*node.skin);
      if (it == skins.end()) it = skins.emplace(*node.skin, skin_placement(reader, *node.skin, h)).first;
      if (it->second) placement = *it->second;
    }
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) instance.transform[4 * r + c] = placement(r, c);
    out.push_back(std::move(instance));
  }
  return out;
}

}  // namespace softdeca::avatar_import::gltf
