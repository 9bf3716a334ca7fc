// The node hierarchy of a glTF and the mesh instances of its scene: the `scene` the file names
// (else its first scene; a file without scenes: every root node), walked depth first with each
// node's children in order, every node placed by the product of its ancestors' transforms and
// its own (a matrix, or translation * rotation * scale). The hierarchy must be what the
// specification allows: children that exist, at most one parent each, no cycle, and here no
// deeper than ImportLimits::max_node_depth; the vertices the scene instances are bounded before
// any mesh is decoded.
//
// A skinned mesh is placed as the specification draws it: by its joints (each joint's global
// transform times its inverse bind matrix), not by its own node. When every joint gives the same
// placement (the scene in its bind pose, as avatar files are) that placement is the mesh's
// transform; a skeleton posed away from its bind pose would deform the mesh rather than place
// it, and the mesh is then placed by its node's global transform, the bind pose as modelled.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "gltf_accessors.h"
#include "import_limits.h"

namespace softdeca::avatar_import::gltf {

struct Instance {
  std::size_t node = 0, mesh = 0;
  std::string name;  // the node's name, else the mesh's, else the nearest named ancestor's
  double transform[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // row-major, mesh -> scene
};

// The scene's mesh instances in traversal order. Throws Problem naming the node or scene at fault.
std::vector<Instance> scene_instances(AccessorReader& reader, const ImportLimits& limits);

}  // namespace softdeca::avatar_import::gltf
