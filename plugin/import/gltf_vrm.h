// VRM avatars name their expressions above the morph targets: VRM 0.x's
// extensions.VRM.blendShapeMaster.blendShapeGroups (a name or presetName, binds of {mesh, index,
// weight 0-100}) and VRM 1.0's extensions.VRMC_vrm.expressions (preset and custom names, binds of
// {node, index, weight 0-1}). A "perfect sync" avatar gives the ARKit names there, over targets
// named otherwise. Each expression that binds a mesh's targets becomes a shape of that mesh under
// the expression's name, its deltas the weighted sum of the bound targets' deltas, unless the
// mesh already has a shape of that name.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "avatar_source.h"
#include "gltf_document.h"
#include "gltf_json.h"

namespace softdeca::avatar_import::gltf {

class Expressions {
 public:
  // The file's VRM expressions in file order (VRM 0.x groups, then VRM 1.0's preset and custom
  // expressions); none for a plain glTF. Throws Problem at a malformed bind.
  explicit Expressions(Document& doc);

  // Appends to `mesh`, the instance of meshes[mesh_index] placed by nodes[node] (`label` names it
  // in errors), the shapes of the expressions that bind its targets (its shapes so far), at most
  // `max_shapes` of them. Each shape's size and the work of each bind are taken from `budget`.
  // Throws Problem at a bind to a target the mesh does not have.
  void add_shapes(std::size_t mesh_index, std::size_t node, const std::string& label, SourceMesh& mesh, std::size_t max_shapes,
                  DecodeBudget& budget) const;

 private:
  struct Bind {
    std::size_t expression = 0;
    std::size_t target = 0;
    double weight = 0;  // 1 is the target's full delta
    std::string where;  // the bind's place in the file, for errors
  };
  void add_vrm0(Document& doc, const Object& vrm);
  void add_vrm1(Document& doc, const Object& vrm);

  std::vector<std::string> names_;
  // The binds of each mesh (VRM 0.x) and each node (VRM 1.0), in expression order: an instance
  // looks at its own binds only.
  std::map<std::size_t, std::vector<Bind>> by_mesh_, by_node_;
};

}  // namespace softdeca::avatar_import::gltf
