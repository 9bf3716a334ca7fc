// How a person looks at a user's avatar: the subject's frame the library reads off its shapes
// (left, up, out of the face; fit/avatar_frame.h) in the avatar's common space, and the fit's
// unit. The fit picture frames the face with it, and a replay writes it for its previews, so
// that a centimetre Z-up FBX is shown from the front with true millimetres.
#pragma once

#include <string>

#include "imported_avatar.h"

namespace softdeca::cli {

struct AvatarView {
  double left[3], up[3], forward[3];  // unit vectors, common space
  double eyes[3];                     // midway between the eyes (the face's centre without eye shapes)
  double metres_per_unit = 1;
};

// The frame of `avatar` (its shapes) with the fit's `metres_per_unit`.
AvatarView avatar_view(const AvatarFile& avatar, double metres_per_unit);

// The fit report's metres_per_unit (softdeca_avatar_fit_get_report's JSON).
double fit_metres_per_unit(const std::string& fit_report);

// JSON: {"metres_per_unit", "parts": [{"first_vertex", "vertex_count", "to_view": 12 numbers}]}
// where to_view is the row-major 3x4 map from a part's own coordinates (as a replay writes its
// frames, part_space.h) to metres in the subject's frame: +X the subject's left, +Y up, +Z out
// of the face, the origin between the eyes.
std::string view_json(const AvatarFile& avatar, const AvatarView& view);

}  // namespace softdeca::cli
