// Whether a fit holds the avatar's face, measured both ways, and the verdict (docs/avatars.md,
// "The fit's quality"). The template's distance to the avatar alone can look perfect while the
// registered template is squeezed into a patch of the face: every template point then lies on
// the avatar. So the avatar's face is measured against the registered template too (how much of
// it the template covers, how far its vertices lie, with no cut-off), and the template's face
// size against the size the avatar's own shapes give; the template's own mean distance to the
// avatar is judged as well.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "geometry/surface_query.h"

namespace softdeca::fit {

// The bounds a fit must meet, the one place they are set (the report carries them). The
// repository's test avatars (docs/avatars.md) pass them with a wide margin; a template squeezed
// into part of the face or stretched past it fails them.
struct QualityBounds {
  double covered_mm = 3.0;         // an avatar face vertex this close to the template is covered
  double min_face_coverage = 0.7;  // share of the avatar's face vertices covered
  double max_median_mm = 1.0;      // the avatar's face vertices' median distance to the template
  double max_p90_mm = 3.0;         // ... and their 90th percentile
  double max_residual_mm = 1.0;    // the registered template's face's mean distance to the avatar
  double min_template_scale = 0.83, max_template_scale = 1.2;  // template face size / avatar's
};
inline constexpr QualityBounds kQualityBounds{};

// What the fit measures on both sides, in the template's frame (metres in, millimetres out).
struct QualityInput {
  // The avatar's face vertices: what its skin-only shapes move (eyes, teeth, tongue left out).
  std::vector<Eigen::Vector3d> avatar_face;
  // What each side's face size is read off (FitQuality::template_scale), the same shapes in the
  // same order on both: the skin-only shapes both move, each one's centre of motion and spread (metres); for a
  // fit by landmarks, the landmarks with no spread. Fewer than 3: no scale.
  struct Side {
    std::vector<Eigen::Vector3d> centres;
    std::vector<double> spreads;
  };
  Side on_template, on_avatar;
  double residual_mm = 0;      // the registered template's face to the avatar's surface, mean
  double metres_per_unit = 1;  // the avatar's unit as the fit took it (named in a reason)
};

struct FitQuality {
  std::size_t face_points = 0;  // avatar face vertices measured
  double face_coverage = 0;     // share within covered_mm of the registered template
  double median_mm = 0, p90_mm = 0, max_mm = 0;  // their distances to it
  // The registered template's face size over the avatar's, each side's size the RMS distance of
  // its shapes' motion from their common centre, every shape weighing the same: sqrt(mean over
  // the shapes of (spread^2 + |centre - mean centre|^2)). A shape's motion weighs each vertex by
  // its share of the surface and by how far the shape moves it, so a denser mesh or a rig's small
  // motions at a region's edge barely change it; a template squeezed into part of the face has a
  // smaller one. 0: not measured.
  double template_scale = 0;
  bool passed = true;
  std::string failed_measure;  // the first measure outside its bounds ("" when passed)
  std::string reason;          // what failed, by how much, the likely cause ("" when passed)
};

// Measures `input` against the registered template skin and judges it by kQualityBounds.
FitQuality fit_quality(const geometry::SurfaceQuery& registered, const QualityInput& input);

}  // namespace softdeca::fit
