#include "shape_names.h"

#include <sstream>
#include <stdexcept>

#include "input_files.h"
#include "softdeca/softdeca.h"

namespace softdeca::avatar_import {

namespace {
constexpr std::uint64_t kMaxNamesFileBytes = 4u << 20;

int rule_index(const std::string& name) {
  int32_t index = -1;
  if (softdeca_blendshape_find_index(name.c_str(), &index) != SOFTDECA_OK) return -1;
  return index;
}

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}
}  // namespace

ShapeNames ShapeNames::from_file(const std::string& path) {
  // Read once, as a regular file within its bound: a FIFO or /dev/zero is refused, not waited on.
  return parse(read_named_file(path, kMaxNamesFileBytes, "a names file"), path);
}

ShapeNames ShapeNames::parse(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  ShapeNames names;
  names.file_ = path;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (number > 100000 || line.size() > 4096) throw std::runtime_error(where + "too long for a names file");
    const std::string text = trim(line.substr(0, line.find('#')));
    if (text.empty()) continue;
    std::size_t split = text.find('\t');
    if (split == std::string::npos) split = text.find('=');
    if (split == std::string::npos) throw std::runtime_error(where + "expected 'rigName<TAB>arkitName' or 'rigName=arkitName'");
    const std::string rig = trim(text.substr(0, split)), arkit = trim(text.substr(split + 1));
    if (rig.empty() || arkit.empty()) throw std::runtime_error(where + "a name is missing");
    int index = -1;
    if (arkit != "none" && arkit != "-") {
      index = rule_index(arkit);
      if (index < 0) throw std::runtime_error(where + "'" + arkit + "' is not an ARKit blendshape name (or none)");
    }
    if (!names.mapped_.emplace(rig, index).second) throw std::runtime_error(where + "'" + rig + "' is listed twice");
  }
  return names;
}

int ShapeNames::index(const std::string& rig_name) const {
  const auto it = mapped_.find(rig_name);
  return it != mapped_.end() ? it->second : rule_index(rig_name);
}

std::size_t ShapeChoice::count() const {
  std::size_t n = 0;
  for (const int c : chosen) n += c >= 0;
  return n;
}

ShapeChoice choose_shapes(const std::vector<std::string>& names, const ShapeNames& rule) {
  ShapeChoice choice;
  choice.chosen.fill(-1);
  std::array<const std::string*, 52> giver{};  // the name that took each shape
  for (std::size_t i = 0; i < names.size(); ++i) {
    const int k = rule.index(names[i]);
    if (k < 0) {
      choice.unused.push_back({i, "no ARKit name"});
    } else if (!giver[k]) {
      giver[k] = &names[i];
      choice.chosen[k] = static_cast<int>(i);
    } else if (*giver[k] == names[i]) {
      // The same name again: FBX lists a shape's in-betweens before its full target.
      choice.unused.push_back({static_cast<std::size_t>(choice.chosen[k]), "an in-between of the shape of the same name after it"});
      choice.chosen[k] = static_cast<int>(i);
    } else {
      choice.unused.push_back({i, "'" + *giver[k] + "' already gives " + softdeca_blendshape_get_name(static_cast<uint32_t>(k))});
    }
  }
  return choice;
}

}  // namespace softdeca::avatar_import
