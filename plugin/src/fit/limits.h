// The sizes of avatar a fit accepts (SOFTDECA_MAX_AVATAR_VERTICES in the C header): a bound on
// what a hostile mesh or fit file can make the library allocate.
#pragma once

#include <cstddef>

namespace softdeca::fit {

constexpr std::size_t kMaxAvatarVertices = 4000000;
constexpr std::size_t kMaxAvatarTriangles = 3 * kMaxAvatarVertices;

}  // namespace softdeca::fit
