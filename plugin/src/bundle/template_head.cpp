#include "bundle/template_head.h"

#include <cmath>
#include <cstdint>

#include "core/binary_reader.h"
#include "core/error.h"
#include "kernels/half.h"

namespace softdeca::bundle {

TemplateHead parse_template_head(const Manifest& m, const Bytes& data) {
  const std::string& f = m.template_head_file;
  BinaryReader in(data.data(), data.size(), f);
  TemplateHead t;
  const auto vh = static_cast<std::size_t>(m.head_vertices), vs = static_cast<std::size_t>(m.skin_vertices);
  t.neutral = in.vector<float>(vh * 3, "the neutral head");
  const auto half = in.vector<std::uint16_t>(kBlendshapeCount * vs * 3, "the shapes");
  t.identity_count = static_cast<std::size_t>(m.template_identity_modes);
  const auto modes = in.vector<std::uint16_t>(t.identity_count * vs * 3, "the identity modes");
  in.finish();
  t.shapes.resize(half.size());
  for (std::size_t i = 0; i < half.size(); ++i) t.shapes[i] = kernels::half_to_float(half[i]);
  t.identity_modes.resize(modes.size());
  for (std::size_t i = 0; i < modes.size(); ++i) {
    t.identity_modes[i] = kernels::half_to_float(modes[i]);
    if (!std::isfinite(t.identity_modes[i])) throw Error(SOFTDECA_ERROR_FORMAT, f + ": an identity mode holds a non-finite value");
  }
  for (const float v : t.neutral)
    if (!std::isfinite(v)) throw Error(SOFTDECA_ERROR_FORMAT, f + ": the neutral head holds a non-finite value");
  for (std::size_t k = 0; k < static_cast<std::size_t>(kBlendshapeCount); ++k) {
    const float* s = t.shape(k, vs);
    for (std::size_t i = 0; i < vs * 3; ++i) {
      if (!std::isfinite(s[i])) throw Error(SOFTDECA_ERROR_FORMAT, f + ": shape " + std::to_string(k) + " holds a non-finite value");
      if (s[i] != 0) t.moves[k] = true;
    }
  }
  return t;
}

}  // namespace softdeca::bundle
