// The skull's two rigid bones, cranium and jaw: their rest shapes scaled per axis (Appendix A)
// and, for pinned bones, their vertices placed by a rigid transform per frame.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "sim/mesh.h"
#include "sim/parameters.h"

namespace softdeca::sim {

struct BoneTransforms {
  Eigen::Isometry3d cranium = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d jaw = Eigen::Isometry3d::Identity();
};

// Rest positions with the cranium's and jaw's vertices scaled about their pivots by
// cranium_scale_* and jaw_scale_*; other vertices unchanged.
Positions scaled_rest(const SimulationMesh& mesh, const ParameterSet& params);

// Pivot of a bone: its own, or the centroid of its rest vertices.
Eigen::Vector3d bone_pivot(const SimulationMesh& mesh, const Bone& bone);

// 1 for every vertex of a pinned bone.
std::vector<char> pinned_mask(const SimulationMesh& mesh);

// Writes the pinned vertices' positions for this frame into x (others untouched).
void place_pinned(const SimulationMesh& mesh, const Positions& scaled, const BoneTransforms& t, Positions& x);

// Throws Error unless the transforms are finite and rigid (orthonormal, det +1).
void check_rigid(const BoneTransforms& t);

}  // namespace softdeca::sim
