#include "gltf_vrm.h"

#include <cmath>

namespace softdeca::avatar_import::gltf {

namespace {
std::string text(std::uint64_t n) { return std::to_string(n); }

std::optional<Object> extension(Document& doc, const char* name) {
  const auto extensions = doc.root().optional_object("extensions");
  return extensions ? extensions->optional_object(name) : std::nullopt;
}

double finite_weight(const Object& bind, double scale) {
  const double w = bind.number_or("weight", 0);
  if (!std::isfinite(w)) bind.fail("weight is not finite");
  return w * scale;
}

// VRM 0.x: binds name meshes, weights are percent.
void add_vrm0(Document& doc, const Object& vrm, std::vector<Expression>& out) {
  const auto master = vrm.optional_object("blendShapeMaster");
  const std::vector<Json>* groups = master ? master->optional_array("blendShapeGroups") : nullptr;
  if (!groups) return;
  for (std::size_t g = 0; g < groups->size(); ++g) {
    const Object group((*groups)[g], master->at("blendShapeGroups") + "[" + text(g) + "]");
    Expression e;
    e.name = group.string_or("name", "");
    if (e.name.empty()) e.name = group.string_or("presetName", "");
    if (e.name.empty()) continue;
    if (const std::vector<Json>* binds = group.optional_array("binds"))
      for (std::size_t b = 0; b < binds->size(); ++b) {
        const Object bind((*binds)[b], group.at("binds") + "[" + text(b) + "]");
        e.binds.push_back({bind.index("mesh", doc.count("meshes"), "meshes"), static_cast<std::size_t>(bind.size("index")),
                           finite_weight(bind, 0.01), bind.where()});
      }
    out.push_back(std::move(e));
  }
}

// VRM 1.0: expressions by name under preset and custom; binds name nodes, weights are 0 to 1.
void add_vrm1(Document& doc, const Object& vrm, std::vector<Expression>& out) {
  const auto expressions = vrm.optional_object("expressions");
  if (!expressions) return;
  for (const char* kind : {"preset", "custom"}) {
    const auto named = expressions->optional_object(kind);
    if (!named) continue;
    for (const auto& [name, value] : named->members()) {
      const Object expression(value, named->at(name));
      Expression e;
      e.name = name;
      e.binds_nodes = true;
      if (const std::vector<Json>* binds = expression.optional_array("morphTargetBinds"))
        for (std::size_t b = 0; b < binds->size(); ++b) {
          const Object bind((*binds)[b], expression.at("morphTargetBinds") + "[" + text(b) + "]");
          const std::size_t node = bind.index("node", doc.count("nodes"), "nodes");
          if (!doc.item("nodes", node).has("mesh")) bind.fail("nodes[" + text(node) + "] has no mesh");
          e.binds.push_back({node, static_cast<std::size_t>(bind.size("index")), finite_weight(bind, 1), bind.where()});
        }
      if (!name.empty()) out.push_back(std::move(e));
    }
  }
}
}  // namespace

std::vector<Expression> vrm_expressions(Document& doc) {
  std::vector<Expression> out;
  if (const auto vrm0 = extension(doc, "VRM")) add_vrm0(doc, *vrm0, out);
  if (const auto vrm1 = extension(doc, "VRMC_vrm")) add_vrm1(doc, *vrm1, out);
  return out;
}

void add_expression_shapes(const std::vector<Expression>& expressions, std::size_t mesh_index, std::size_t node, const std::string& label,
                           SourceMesh& mesh, DecodeBudget& budget) {
  const std::size_t own = mesh.shapes.size();
  const auto named = [&](const std::string& name) {
    for (const SourceShape& s : mesh.shapes)
      if (s.name == name) return true;
    return false;
  };
  for (const Expression& e : expressions) {
    std::vector<const ExpressionBind*> binds;
    for (const ExpressionBind& b : e.binds)
      if (b.owner == (e.binds_nodes ? node : mesh_index)) binds.push_back(&b);
    if (binds.empty() || named(e.name)) continue;
    budget.take(4 * mesh.vertices.size(), "the VRM expression '" + e.name + "'");
    SourceShape shape{e.name, std::vector<float>(mesh.vertices.size(), 0.0f)};
    for (const ExpressionBind* b : binds) {
      if (b->target >= own)
        throw Problem(b->where, "index " + text(b->target) + " is not one of the " + text(own) + " morph targets of " + label);
      const std::vector<float>& delta = mesh.shapes[b->target].deltas;
      for (std::size_t i = 0; i < delta.size() && i < shape.deltas.size(); ++i) shape.deltas[i] += static_cast<float>(b->weight * delta[i]);
    }
    mesh.shapes.push_back(std::move(shape));
  }
}

}  // namespace softdeca::avatar_import::gltf
