// VRM avatars name their expressions above the morph targets: VRM 0.x's
// extensions.VRM.blendShapeMaster.blendShapeGroups (a name or presetName, binds of {mesh, index,
// weight 0-100}) and VRM 1.0's extensions.VRMC_vrm.expressions (preset and custom names, binds of
// {node, index, weight 0-1}). A "perfect sync" avatar gives the ARKit names there, over targets
// named otherwise. Each expression that binds a mesh's targets becomes a shape of that mesh under
// the expression's name, its deltas the weighted sum of the bound targets' deltas, unless the
// mesh already has a shape of that name.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "avatar_source.h"
#include "gltf_document.h"
#include "gltf_json.h"

namespace softdeca::avatar_import::gltf {

struct ExpressionBind {
  std::size_t owner = 0;   // a mesh index (VRM 0.x) or a node index (VRM 1.0)
  std::size_t target = 0;  // the morph target
  double weight = 0;       // 1 is the target's full delta
  std::string where;       // the bind's place in the file, for errors
};

struct Expression {
  std::string name;
  bool binds_nodes = false;  // VRM 1.0: binds name nodes, not meshes
  std::vector<ExpressionBind> binds;
};

// The file's VRM expressions in file order (VRM 0.x groups, then VRM 1.0's preset and custom
// expressions); none for a plain glTF. Throws Problem at a malformed bind.
std::vector<Expression> vrm_expressions(Document& doc);

// Appends to `mesh`, the instance of meshes[mesh_index] placed by nodes[node] (`label` names it
// in errors), the shapes of the expressions that bind its targets (its shapes so far).
// Throws Problem at a bind to a target the mesh does not have.
void add_expression_shapes(const std::vector<Expression>& expressions, std::size_t mesh_index, std::size_t node, const std::string& label,
                           SourceMesh& mesh, DecodeBudget& budget);

}  // namespace softdeca::avatar_import::gltf
