// The template head a bundle carries for fitting users' avatars (docs/bundle.md, "Template
// head"): the template's neutral head, its 52 ARKit shapes and its identity modes over the skin.
// Read and checked once at load.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "bundle/bundle_files.h"
#include "bundle/manifest.h"

namespace softdeca::bundle {

struct TemplateHead {
  std::vector<float> neutral;  // head_vertices x 3, metres
  std::vector<float> shapes;   // 52 x skin_vertices x 3 deltas (stored as float16)
  std::array<bool, kBlendshapeCount> moves{};  // shape k moves some skin vertex
  std::vector<float> identity_modes;           // K x skin_vertices x 3 (scaled: h about N(0, 1))
  std::size_t identity_count = 0;              // K

  const float* shape(std::size_t k, std::size_t skin_vertices) const { return shapes.data() + k * skin_vertices * 3; }
  std::size_t bytes() const { return (neutral.size() + shapes.size() + identity_modes.size()) * sizeof(float); }
};

// Throws Error(FORMAT) naming the problem: a size that does not match the manifest, a
// non-finite value.
TemplateHead parse_template_head(const Manifest& manifest, const Bytes& data);

}  // namespace softdeca::bundle
