#include "gltf_vrm.h"

#include <cmath>
#include <set>

namespace softdeca::avatar_import::gltf {

namespace {
std::string text(std::uint64_t n) { return std::to_string(n); }

double finite_weight(const Object& bind, double scale) {
  const double w = bind.number_or("weight", 0);
  if (!std::isfinite(w)) bind.fail("weight is not finite");
  return w * scale;
}
}  // namespace

Expressions::Expressions(Document& doc) {
  const auto extensions = doc.root().optional_object("extensions");
  if (!extensions) return;
  if (const auto vrm0 = extensions->optional_object("VRM")) add_vrm0(doc, *vrm0);
  if (const auto vrm1 = extensions->optional_object("VRMC_vrm")) add_vrm1(doc, *vrm1);
}

// VRM 0.x: binds name meshes, weights are percent.
void Expressions::add_vrm0(Document& doc, const Object& vrm) {
  const auto master = vrm.optional_object("blendShapeMaster");
  const std::vector<Json>* groups = master ? master->optional_array("blendShapeGroups") : nullptr;
  if (!groups) return;
  for (std::size_t g = 0; g < groups->size(); ++g) {
    const Object group((*groups)[g], master->at("blendShapeGroups") + "[" + text(g) + "]");
    std::string name = group.string_or("name", "");
    if (name.empty()) name = group.string_or("presetName", "");
    const std::vector<Json>* binds = group.optional_array("binds");
    if (name.empty() || !binds) continue;
    for (std::size_t b = 0; b < binds->size(); ++b) {
      const Object bind((*binds)[b], group.at("binds") + "[" + text(b) + "]");
      const std::size_t mesh = bind.index("mesh", doc.count("meshes"), "meshes");
      by_mesh_[mesh].push_back({names_.size(), static_cast<std::size_t>(bind.size("index")), finite_weight(bind, 0.01), bind.where()});
    }
    names_.push_back(name);
  }
}

// VRM 1.0: expressions by name under preset and custom; binds name nodes, weights are 0 to 1.
void Expressions::add_vrm1(Document& doc, const Object& vrm) {
  const auto expressions = vrm.optional_object("expressions");
  if (!expressions) return;
  for (const char* kind : {"preset", "custom"}) {
    const auto named = expressions->optional_object(kind);
    if (!named) continue;
    for (const auto& [name, value] : named->members()) {
      const Object expression(value, named->at(name));
      const std::vector<Json>* binds = expression.optional_array("morphTargetBinds");
      if (name.empty() || !binds) continue;
      for (std::size_t b = 0; b < binds->size(); ++b) {
        const Object bind((*binds)[b], expression.at("morphTargetBinds") + "[" + text(b) + "]");
        const std::size_t node = bind.index("node", doc.count("nodes"), "nodes");
        if (!doc.item("nodes", node).has("mesh")) bind.fail("nodes[" + text(node) + "] has no mesh");
        by_node_[node].push_back({names_.size(), static_cast<std::size_t>(bind.size("index")), finite_weight(bind, 1), bind.where()});
      }
      names_.push_back(name);
    }
  }
}

void Expressions::add_shapes(std::size_t mesh_index, std::size_t node, const std::string& label, SourceMesh& mesh, std::size_t max_shapes,
                             DecodeBudget& budget) const {
  std::vector<const Bind*> binds;  // this instance's, in expression order (VRM 0.x's come first)
  for (const auto* list : {&by_mesh_, &by_node_}) {
    const auto it = list->find(list == &by_mesh_ ? mesh_index : node);
    if (it != list->end())
      for (const Bind& b : it->second) binds.push_back(&b);
  }
  if (binds.empty()) return;
  const std::size_t own = mesh.shapes.size(), floats = mesh.vertices.size();
  std::set<std::string> taken;
  for (const SourceShape& s : mesh.shapes) taken.insert(s.name);
  std::size_t added = 0;
  for (std::size_t first = 0; first < binds.size();) {
    std::size_t end = first;
    while (end < binds.size() && binds[end]->expression == binds[first]->expression) ++end;
    const std::string& name = names_[binds[first]->expression];
    if (taken.insert(name).second) {
      if (++added > max_shapes)
        throw Problem(label, "more than " + text(max_shapes) + " VRM expressions bind its morph targets, more than a mesh may have");
      const std::string where = "the VRM expression '" + name + "' of " + label;
      budget.take(sizeof(SourceShape) + name.size() + 4 * floats * (1 + end - first), where);  // its deltas, and a pass per bind
      SourceShape shape{name, std::vector<float>(floats, 0.0f)};
      for (std::size_t b = first; b < end; ++b) {
        if (binds[b]->target >= own)
          throw Problem(binds[b]->where,
                        "index " + text(binds[b]->target) + " is not one of the " + text(own) + " morph targets of " + label);
        const std::vector<float>& delta = mesh.shapes[binds[b]->target].deltas;
        for (std::size_t i = 0; i < delta.size() && i < floats; ++i) shape.deltas[i] += static_cast<float>(binds[b]->weight * delta[i]);
      }
      mesh.shapes.push_back(std::move(shape));
    }
    first = end;
  }
}

}  // namespace softdeca::avatar_import::gltf
