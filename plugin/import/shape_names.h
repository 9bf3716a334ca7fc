// Which ARKit shape each of a rig's own shape names gives: the product's one rule
// (softdeca_blendshape_find_index, docs/avatars.md), unless a mapping file says otherwise for a name.
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace softdeca::avatar_import {

class ShapeNames {
 public:
  ShapeNames() = default;  // the rule alone
  // A mapping file: one "rigName<TAB>arkitName" or "rigName=arkitName" a line; '#' starts a
  // comment; arkitName "none" (or "-") keeps the rig's shape out. Names it lists are matched
  // exactly and override the rule; the rest follow the rule. Throws std::runtime_error naming
  // the file and line.
  static ShapeNames from_file(const std::string& path);
  // The same from the text of such a file; `path` names it in errors (and is file()).
  static ShapeNames parse(const std::string& text, const std::string& path);

  int index(const std::string& rig_name) const;  // 0..51, or -1
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::map<std::string, int> mapped_;
};

struct UnusedShape {
  std::size_t shape;   // index into the names given to choose_shapes
  std::string reason;
};

// The shapes of one mesh chosen for the 52 ARKit shapes, in the names' order: the first name
// that gives a shape wins; a name repeated (FBX's in-between shapes come first) gives its last
// occurrence, the full shape. Every name not chosen is listed with the reason.
struct ShapeChoice {
  std::array<int, 52> chosen;  // index into the names, -1 for a shape the mesh lacks
  std::vector<UnusedShape> unused;
  std::size_t count() const;
};
ShapeChoice choose_shapes(const std::vector<std::string>& names, const ShapeNames& rule);

}  // namespace softdeca::avatar_import
