// Guide points for the registration from what every ARKit rig shares with the template: how a
// vertex responds to the 52 shapes. A template vertex that the shapes move strongly is matched
// to the nearby avatar vertex whose responses (each shape's motion over its typical size on
// that mesh, so amplitudes and units cancel) are most alike.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "fit/avatar_fit.h"
#include "fit/registration.h"

namespace softdeca::fit {

struct ShapeInputs {
  const TemplateData& t;
  const AvatarMesh& a;
  const std::vector<uint8_t>& template_face;  // per template skin vertex
  const std::vector<uint8_t>& avatar_face;    // per avatar vertex
  const std::vector<uint8_t>& avatar_skin;    // per avatar vertex: may be matched (skin, one copy per position)
};

// `template_skin`: the template's skin; `avatar`: the avatar placed in the template's frame;
// `linear`: the placement's linear part (turns the avatar's deltas into the template's frame).
std::vector<Guide> shape_guides(const ShapeInputs& in, const Points& template_skin, const Points& avatar,
                                const Eigen::Matrix3d& linear);

}  // namespace softdeca::fit
