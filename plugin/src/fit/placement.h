// Where a user's avatar sits in the template's frame: its unit, its axes and the rigid motion
// (or similarity) that takes it onto the template, read off its ARKit shapes or, for an avatar
// without shapes, off the bundle's landmarks on it. A step of the fit (fit/avatar_fit.h).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "fit/avatar_fit.h"

namespace softdeca::fit {

// Row i of a packed xyz float array.
inline Eigen::Vector3d row3(const float* p, std::size_t i) { return {p[3 * i], p[3 * i + 1], p[3 * i + 2]}; }

// Kabsch (Umeyama with `scale`): the rotation (no reflection), scale and translation taking src
// onto dst; without `scale`, the scale is 1.
void kabsch(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, Eigen::Matrix3d& r,
            Eigen::Vector3d& t, double* scale = nullptr);

// Where an avatar is: its frame, its unit and the placement into the template's frame.
struct Located {
  AvatarFrame frame;
  double unit = 1;
  bool mirrored = false;
  Placement place;
};

// From the shapes: the frame read off them, then the rigid motion that best takes each shape's
// centre of motion onto the template's. Both hands are tried: the one whose Left and Right
// shapes land on the template's wins (the frame's own guess from the forward shapes or normals
// can be fooled by an unusual rig). `unit_option` > 0 overrides the unit read.
Located locate_by_shapes(const AvatarMesh& a, const AvatarFrame& tframe, double unit_option);

// From the bundle's landmarks on an avatar without ARKit shapes: the similarity (either hand)
// that best takes them onto the template's; the face is what lies near the template's face.
Located locate_by_landmarks(const TemplateData& t, const AvatarMesh& a, const AvatarFrame& tframe, double unit_option);

}  // namespace softdeca::fit
