// The template identity closest to an avatar: the bundle's identity modes (template head)
// fitted to where the template's skin vertices land on the avatar (where the registration
// starts), then to the avatar's surface itself (what the identity code is read off).
#pragma once

#include <functional>
#include <vector>

#include "fit/avatar_fit.h"
#include "fit/registration.h"
#include "geometry/surface_query.h"

namespace softdeca::fit {

// The skin of identity h: the template plus h . modes.
Points identity_points(const TemplateData& t, const std::vector<float>& h);

// Identity coefficients whose skin best meets the matches (one per skin vertex, weight 0: none):
// min sum w |T0 + M h - target|^2 + prior |h|^2, the modes scaled so that h is about N(0, 1);
// `prior`: a match's error, squared (metres^2). Reweighted (Cauchy): a part the identity modes
// cannot explain (a remesh's cut ears, a stylised nose) does not pull the whole head.
std::vector<float> fit_identity(const TemplateData& t, const std::vector<Match>& matches, const Points& tskin, double prior);

// The identity refined against the avatar's surface itself: point-to-plane ICP over the
// coefficients and a small rigid motion (discarded: the placement's error, not the identity's).
// Point targets carry the registration's sliding along the skin, which the modes then take for
// shape; distances to the surface do not. Every skin vertex takes part; `outside`: surface
// points to ignore (the avatar's open boundary).
std::vector<float> refine_identity(const TemplateData& t, const geometry::SurfaceQuery& surface,
                                   const std::function<bool(const geometry::SurfacePoint&)>& outside,
                                   std::vector<float> h);

}  // namespace softdeca::fit
