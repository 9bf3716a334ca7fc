// The template identity closest to an avatar: the bundle's identity modes (template head)
// fitted to where the template's skin vertices land on the avatar. Its head is where the
// registration starts and what the identity code is read off (fit/avatar_fit.h).
#pragma once

#include <vector>

#include "fit/avatar_fit.h"
#include "fit/registration.h"

namespace softdeca::fit {

// The skin of identity h: the template plus h . modes.
Points identity_points(const TemplateData& t, const std::vector<float>& h);

// Identity coefficients whose skin best meets the matches (one per skin vertex, weight 0: none):
// min sum w |T0 + M h - target|^2 + prior |h|^2, the modes scaled so that h is about N(0, 1);
// `prior`: a match's error, squared (metres^2). Reweighted (Cauchy): a part the identity modes
// cannot explain (a remesh's cut ears, a stylised nose) does not pull the whole head.
std::vector<float> fit_identity(const TemplateData& t, const std::vector<Match>& matches, const Points& tskin, double prior);

}  // namespace softdeca::fit
