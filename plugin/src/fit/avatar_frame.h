// Where a user's avatar has its face, which way it faces and in which unit, read off its own
// ARKit blendshapes: any rig's shapes move the face and nothing else, the Left shapes move the
// subject's left side, the eye and brow shapes sit above the mouth and jaw shapes, and a face's
// eyes are about 6 cm apart. No landmarks needed; a whole body, any unit (mm to m) and any axis
// convention (Y-up, Z-up) work. The first step of fitting an avatar (docs/avatars.md).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace softdeca::fit {

constexpr std::size_t kShapes = 52;

// An avatar's neutral mesh and its ARKit shapes in canonical order (stream/arkit_names.h), as
// deltas from the neutral; a null pointer for a shape the rig lacks. Row-major xyz floats,
// right-handed coordinates (the Unity layer converts its left-handed mesh space).
struct AvatarShapes {
  const float* neutral = nullptr;
  std::size_t vertex_count = 0;
  std::array<const float*, kShapes> deltas{};
  // Optional, but what the unit's table assumes: each vertex weighs by its share of the
  // surface (without triangles, 1 each); and the face's normals, where no forward shape is.
  const int32_t* triangles = nullptr;
  std::size_t triangle_count = 0;
};

struct AvatarFrame {
  // Unit vectors in the avatar's coordinates: the subject's left, up, and out of the face
  // (left x up for a right-handed mesh, as the template's +X, +Y, +Z; its opposite for a
  // mirrored one).
  Eigen::Vector3d left, up, forward;
  Eigen::Vector3d eyes = Eigen::Vector3d::Zero();  // midway between the eyes (zero without eye shapes)
  double eye_distance = 0;  // between the eyes' centres of motion, avatar units (0 without eye shapes)
  // The unit: the template's distance between each Left/Right pair's sides (where one side's
  // shape moves more than the other's) over the avatar's, the median over the pairs, snapped to
  // mm, cm, inch, dm or m when within 25 %.
  double metres_per_unit = 1;
  double metres_per_unit_measured = 1;
  std::string up_axis;        // the avatar axis closest to up: "+Y", "+Z", "-X", ...
  // Left-handed coordinates (a mirrored export): the forward shapes (jawForward, mouthPucker,
  // mouthFunnel, cheekPuff), else the face's normals, point along -(left x up).
  bool mirrored = false;
  std::vector<uint8_t> face;  // per vertex: 1 where some ARKit shape moves it
  // Per shape: whether it moves a vertex, its motion-weighted centre (avatar coordinates) and
  // spread (the RMS distance of what it moves from that centre, weighted alike; avatar units).
  std::array<bool, kShapes> moves{};
  std::array<Eigen::Vector3d, kShapes> centres{};
  std::array<double, kShapes> spreads{};
  std::size_t face_vertices = 0;
  std::size_t shapes_used = 0;
};

// Each shape's motion-weighted centre and spread as avatar_frame reads them (`moves` false where
// the shape moves nothing), without the frame: for a mesh known to be a face, such as the
// registered template, whose shapes tell its face's size (fit/fit_quality.h).
struct ShapeCentres {
  std::array<bool, kShapes> moves{};
  std::array<Eigen::Vector3d, kShapes> centres{};
  std::array<double, kShapes> spreads{};
};
ShapeCentres shape_centres(const AvatarShapes& shapes);

// A measured metres-per-unit snapped to mm, cm, inch, dm or m when within 25 %.
double snap_unit(double measured);

// The avatar axis closest to a direction: "+Y", "-Z", ...
std::string axis_name(const Eigen::Vector3d& direction);

// Throws softdeca::Error (invalid argument) with a message a user can act on: no vertices,
// non-finite values, no ARKit shape that moves anything, no Left/Right pair or no shapes
// above and below to tell the orientation from.
AvatarFrame avatar_frame(const AvatarShapes& shapes);

}  // namespace softdeca::fit
