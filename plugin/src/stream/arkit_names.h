// ARKit's 52 blendshape names in the canonical order of every interface (docs/ARCHITECTURE.md, Conventions): the
// alphabetical order of ARFaceAnchor.BlendShapeLocation, browDownLeft = 0 ... tongueOut = 51.
// The names come from plugin/data/face_names.json (embedded at build time); adapters map their
// own orders and spellings onto this order.
#pragma once

#include <cstddef>
#include <string_view>

namespace softdeca::stream {

constexpr std::size_t kBlendshapeCount = 52;

// Canonical name of shape `index` ("browDownLeft"), or nullptr when index >= 52.
const char* blendshape_name(std::size_t index);

// Index of a canonical name, or -1. `ignore_first_case` also accepts the first letter in upper
// case ("EyeBlinkLeft"), the spelling of Live Link Face.
int blendshape_index(std::string_view name, bool ignore_first_case = false);

}  // namespace softdeca::stream
