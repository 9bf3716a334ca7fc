// The ranges a fit lies in: the sizes of avatar it accepts (SOFTDECA_MAX_AVATAR_VERTICES in the
// C header), a bound on what a hostile mesh or fit file can make the library allocate, and the
// ranges of its values, which a fit is checked against when it is made and when it is loaded
// (fit/fit_file.h): a fit the library makes always loads, a fit file outside them never does.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

namespace softdeca::fit {

constexpr std::size_t kMaxAvatarVertices = 4000000;
constexpr std::size_t kMaxAvatarTriangles = 3 * kMaxAvatarVertices;

// The avatar's unit (metres per unit of its coordinates), given or read off its shapes: from a
// micrometre (a unit whose cube still is a double far from underflow) to a kilometre.
constexpr double kMinMetresPerUnit = 1e-6;
constexpr double kMaxMetresPerUnit = 1000;
// "1e-06 to 1000", for messages.
inline std::string metres_per_unit_range() {
  char text[64];
  std::snprintf(text, sizeof text, "%g to %g", kMinMetresPerUnit, kMaxMetresPerUnit);
  return text;
}

// How far from the registered skin an avatar vertex is embedded on it (metres): the signed
// offset along the skin's normal never exceeds it.
constexpr double kEmbeddingReach = 0.010;

// The registered template head stays near the template's own (well within a metre of its
// origin): no registered vertex lies farther from the origin than this (metres).
constexpr double kRegisteredReach = 10;

// Where the placement may put the avatar's origin (metres from the template's): float
// coordinates farther out than 10 km have no millimetre left for a face.
constexpr double kPlacementReach = 10000;

// The template identity's coefficients are about N(0, 1): none is near a thousand.
constexpr double kMaxIdentityCoefficient = 1000;

}  // namespace softdeca::fit
