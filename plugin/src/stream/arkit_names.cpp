#include "stream/arkit_names.h"

#include <array>
#include <cctype>

#include "stream/face_names_table.h"

namespace softdeca::stream {
namespace {
constexpr std::array<const char*, kBlendshapeCount> kNames = SOFTDECA_ARKIT_BLENDSHAPE_NAMES;
static_assert(SOFTDECA_ARKIT_BLENDSHAPE_COUNT == kBlendshapeCount, "data/face_names.json: 52 ARKit blendshapes");

bool same(std::string_view canonical, std::string_view name, bool ignore_first_case) {
  if (canonical.size() != name.size() || name.empty()) return false;
  const bool first_ok =
      canonical[0] == name[0] ||
      (ignore_first_case && std::tolower(static_cast<unsigned char>(name[0])) == canonical[0]);
  return first_ok && canonical.substr(1) == name.substr(1);
}
}  // namespace

const char* blendshape_name(std::size_t index) {
  return index < kNames.size() ? kNames[index] : nullptr;
}

int blendshape_index(std::string_view name, bool ignore_first_case) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (same(kNames[i], name, ignore_first_case)) return static_cast<int>(i);
  return -1;
}

}  // namespace softdeca::stream
