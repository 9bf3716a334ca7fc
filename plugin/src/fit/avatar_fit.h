// Fitting a user's avatar to a bundle's template (docs/avatars.md): the face, its axes and unit
// from the avatar's own shapes (fit/avatar_frame.h), a placement into the template's frame, the
// template's skin registered to the avatar's face (fit/registration.h), guided by the shapes'
// semantics, and every avatar vertex that follows the face embedded on the registered skin.
// The result is what the runtime needs to run the models on the registered template and carry
// their output back to the avatar's own vertices (runtime/fitted_avatar.h).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fit/avatar_frame.h"

namespace softdeca::fit {

// What the bundle brings: the template head and its shapes over the skin (metres, the
// template's frame), the skin's triangles.
struct TemplateData {
  const float* head_neutral = nullptr;  // head_vertices x 3
  std::size_t head_vertices = 0, skin_vertices = 0;
  const float* shapes = nullptr;  // 52 x skin_vertices x 3 deltas
  std::array<bool, kShapes> moves{};
  const float* identity_modes = nullptr;  // K x skin_vertices x 3 (h about N(0, 1)); may be none
  std::size_t identity_count = 0;         // K
  const std::int32_t* skin_triangles = nullptr;
  std::size_t skin_triangle_count = 0;
  // The bundle's landmarks on the skin: a triangle row and barycentric weights each (optional).
  std::vector<std::int32_t> landmark_triangle;
  std::vector<std::array<double, 3>> landmark_bary;
};

// The user's avatar in its own coordinates and units.
struct AvatarMesh {
  const float* neutral = nullptr;
  std::size_t vertex_count = 0;
  const std::int32_t* triangles = nullptr;
  std::size_t triangle_count = 0;
  std::array<const float*, kShapes> deltas{};  // null where the rig lacks the shape
  const float* landmarks = nullptr;             // the bundle's landmarks on the avatar, or null
  std::size_t landmark_count = 0;
};

struct FitOptions {
  double metres_per_unit = 0;  // 0: read off the shapes
  int iterations = 0;          // 0: the registration's default
  std::function<void(const char* step, double share)> progress;  // may be empty
};

// x_template = linear * x_avatar + offset: the avatar's unit to metres, its axes to the
// template's (+X left, +Y up, +Z forward), a mirrored mesh through a reflection.
struct Placement {
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d to_template(const Eigen::Vector3d& x) const { return linear * x + offset; }
};

// Avatar vertices that follow the face, each on a triangle of the registered skin.
struct Embedding {
  std::vector<std::int32_t> vertex, triangle;  // avatar vertex, template skin triangle
  std::vector<float> bary;                     // 3 per entry
  std::vector<float> offset;                   // signed distance along the skin's normal (metres)
  std::vector<float> weight;                   // (0, 1]: 1 on the face, fading away from it
  std::size_t size() const { return vertex.size(); }
};

// Where each template skin vertex reads the avatar's shapes: a triangle of the avatar and its
// weights, and how much the avatar's shape counts there (1 on the avatar's surface, 0 far from
// it, where the template's own shape is used).
struct ShapeSource {
  std::vector<std::int32_t> corners;  // 3 avatar vertices per skin vertex
  std::vector<float> bary;            // 3 per skin vertex
  std::vector<float> weight;  // per skin vertex
};

enum class ShapeOrigin : std::uint8_t { None = 0, Avatar = 1, Template = 2 };

struct AvatarFit {
  std::string mesh_sha256;  // of the avatar's neutral and triangles (fit/mesh_hash.h)
  std::size_t vertex_count = 0, triangle_count = 0;
  Placement placement;
  std::vector<float> registered;  // head_vertices x 3: the registered template head (metres)
  // The template identity closest to the avatar's surface (K coefficients over the identity
  // modes): what the identity code is read off.
  std::vector<float> identity;
  ShapeSource source;
  std::array<ShapeOrigin, kShapes> origin{};
  Embedding embedding;
  std::string report;  // JSON object: the report's facts and the quality verdict (fit/fit_quality.h)
};

// Throws softdeca::Error (invalid argument) with a message a user can act on.
AvatarFit fit_avatar(const TemplateData& t, const AvatarMesh& avatar, const FitOptions& options);

// The skin of the template identity `fit.identity` (skin_vertices x 3, metres).
std::vector<float> identity_skin(const TemplateData& t, const AvatarFit& fit);

// The 52 shapes of the registered template head (52 x head_vertices x 3, non-skin rows zero):
// the avatar's own carried through the fit where it has them, else the template's.
std::vector<float> carried_shapes(const TemplateData& t, const AvatarMesh& avatar, const AvatarFit& fit);

}  // namespace softdeca::fit
