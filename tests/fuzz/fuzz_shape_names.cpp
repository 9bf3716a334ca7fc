// A names file (import/shape_names.cpp) on any text, then the shapes it chooses among the rig
// names of that text: it parses or refuses with std::runtime_error; every name maps to an
// ARKit shape or to none; every name given to choose_shapes is either chosen for exactly one
// shape or listed as unused, and a chosen name gives the shape it is chosen for.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "fuzz_check.h"
#include "shape_names.h"

using namespace softdeca::avatar_import;

namespace {
// Every word of the text (split at white space, '=' and '#'): rig names as a file would list them.
std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::string word;
  for (const char c : text) {
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '=' || c == '#') {
      if (!word.empty()) out.push_back(word);
      word.clear();
    } else {
      word += c;
    }
  }
  if (!word.empty()) out.push_back(word);
  return out;
}

void check_choice(const std::vector<std::string>& names, const ShapeNames& rule) {
  const ShapeChoice choice = choose_shapes(names, rule);
  FUZZ_CHECK(choice.count() + choice.unused.size() == names.size());
  std::vector<int> times(names.size(), 0);
  for (std::size_t k = 0; k < 52; ++k) {
    const int c = choice.chosen[k];
    if (c < 0) continue;
    FUZZ_CHECK(static_cast<std::size_t>(c) < names.size());
    FUZZ_CHECK(rule.index(names[static_cast<std::size_t>(c)]) == static_cast<int>(k));
    ++times[static_cast<std::size_t>(c)];
  }
  for (const UnusedShape& u : choice.unused) {
    FUZZ_CHECK(u.shape < names.size() && !u.reason.empty());
    ++times[u.shape];
  }
  for (const int t : times) FUZZ_CHECK(t == 1);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> names = words(text);
  if (names.size() > 256) names.resize(256);
  for (const std::string& name : names) FUZZ_CHECK(ShapeNames().index(name) >= -1 && ShapeNames().index(name) < 52);
  check_choice(names, ShapeNames());
  try {
    const ShapeNames mapped = ShapeNames::parse(text, "fuzz.names");
    FUZZ_CHECK(mapped.file() == "fuzz.names");
    for (const std::string& name : names) FUZZ_CHECK(mapped.index(name) >= -1 && mapped.index(name) < 52);
    check_choice(names, mapped);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
