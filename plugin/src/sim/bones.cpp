#include "sim/bones.h"

#include <cmath>

#include "core/error.h"

namespace softdeca::sim {

Eigen::Vector3d bone_pivot(const SimulationMesh& mesh, const Bone& bone) {
  if (bone.pivot.allFinite()) return bone.pivot;
  if (bone.vertices.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int32_t v : bone.vertices) c += mesh.rest.row(v).transpose();
  return c / static_cast<double>(bone.vertices.size());
}

Positions scaled_rest(const SimulationMesh& mesh, const ParameterSet& params) {
  Positions x = mesh.rest;
  auto scale = [&](const Bone& bone, Param sx, Param sy, Param sz) {
    const Eigen::RowVector3d s(params.global(sx), params.global(sy), params.global(sz));
    if (s == Eigen::RowVector3d::Ones()) return;  // keep the rest exact
    const Eigen::RowVector3d pivot = bone_pivot(mesh, bone).transpose();
    for (int32_t v : bone.vertices) x.row(v) = pivot + (mesh.rest.row(v) - pivot).cwiseProduct(s);
  };
  scale(mesh.cranium, Param::cranium_scale_x, Param::cranium_scale_y, Param::cranium_scale_z);
  scale(mesh.jaw, Param::jaw_scale_x, Param::jaw_scale_y, Param::jaw_scale_z);
  return x;
}

std::vector<char> pinned_mask(const SimulationMesh& mesh) {
  std::vector<char> pinned(static_cast<std::size_t>(mesh.vertex_count()), 0);
  for (const Bone* b : {&mesh.cranium, &mesh.jaw})
    if (b->pinned)
      for (int32_t v : b->vertices) pinned[static_cast<std::size_t>(v)] = 1;
  return pinned;
}

void place_pinned(const SimulationMesh& mesh, const Positions& scaled, const BoneTransforms& t, Positions& x) {
  auto place = [&](const Bone& bone, const Eigen::Isometry3d& T) {
    if (!bone.pinned) return;
    for (int32_t v : bone.vertices) x.row(v) = (T * scaled.row(v).transpose()).transpose();
  };
  place(mesh.cranium, t.cranium);
  place(mesh.jaw, t.jaw);
}

void check_rigid(const BoneTransforms& t) {
  for (const auto* T : {&t.cranium, &t.jaw}) {
    const char* name = T == &t.cranium ? "cranium" : "jaw";
    require(T->matrix().allFinite(), std::string(name) + " transform is not finite", SOFTDECA_ERROR_NON_FINITE);
    const Eigen::Matrix3d R = T->linear();
    require((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-5 && R.determinant() > 0,
            std::string(name) + " transform is not a rigid motion (rotation part must be orthonormal, det +1)");
  }
}

}  // namespace softdeca::sim
