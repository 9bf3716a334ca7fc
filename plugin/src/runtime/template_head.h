// The template head a bundle carries for fitting users' avatars (docs/bundle.md, "Template
// head"): the template's neutral head and its 52 ARKit shapes over the skin. Read and checked
// once at load.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "runtime/bundle_files.h"
#include "runtime/manifest.h"

namespace softdeca::runtime {

struct TemplateHead {
  std::vector<float> neutral;  // head_vertices x 3, metres
  std::vector<float> shapes;   // 52 x skin_vertices x 3 deltas (stored as float16)
  std::array<bool, kBlendshapeCount> moves{};  // shape k moves some skin vertex

  const float* shape(std::size_t k, std::size_t skin_vertices) const { return shapes.data() + k * skin_vertices * 3; }
  std::size_t bytes() const { return (neutral.size() + shapes.size()) * sizeof(float); }
};

// Throws Error(FORMAT) naming the problem: a size that does not match the manifest, a
// non-finite value.
TemplateHead parse_template_head(const Manifest& manifest, const Bytes& data);

}  // namespace softdeca::runtime
