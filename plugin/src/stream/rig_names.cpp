#include "stream/rig_names.h"

#include <cctype>
#include <string>
#include <vector>

#include "stream/arkit_names.h"

namespace softdeca::stream {
namespace {

constexpr std::size_t kMaxName = 256;

// Anything but an ASCII letter or digit separates words: . _ - : | / spaces, and bytes of other
// scripts (a name in another alphabet has no ARKit words).
bool is_separator(char c) {
  const unsigned char u = static_cast<unsigned char>(c);
  return u >= 0x80 || std::isalnum(u) == 0;
}
bool is_upper(char c) { return std::isupper(static_cast<unsigned char>(c)) != 0; }
bool is_lower(char c) { return std::islower(static_cast<unsigned char>(c)) != 0; }
bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

// Lower-case words of `name`: a new word at a separator, where a lower-case letter meets an
// upper-case one ("eyeBlink"), and where letters meet digits ("AK07Eye", "blendShape1").
std::vector<std::string> words(std::string_view name) {
  std::vector<std::string> out;
  std::string word;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (is_separator(c)) {
      if (!word.empty()) out.push_back(word), word.clear();
      continue;
    }
    if (!word.empty()) {
      const char p = name[i - 1];
      if ((is_lower(p) && is_upper(c)) || (is_digit(p) != is_digit(c))) out.push_back(word), word.clear();
    }
    word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (!word.empty()) out.push_back(word);
  return out;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

int rig_blendshape_index(std::string_view name) {
  if (name.empty() || name.size() > kMaxName) return -1;
  std::vector<std::string> w = words(name);
  if (w.empty()) return -1;
  // A trailing side letter ("eyeBlink_L", "eyeBlink.R", "eyeBlinkL" all end in the word "l"
  // or "r"); "left"/"right" are canonical words already.
  if (w.back() == "l") w.back() = "left";
  else if (w.back() == "r") w.back() = "right";
  static const auto canonical = [] {
    std::vector<std::string> c;
    for (std::size_t i = 0; i < kBlendshapeCount; ++i) c.push_back(lower(blendshape_name(i)));
    return c;
  }();
  // Longest trailing run first: "mouthLeft" must not win over a longer name ending in it.
  for (std::size_t start = 0; start < w.size(); ++start) {
    std::string joined;
    for (std::size_t k = start; k < w.size(); ++k) joined += w[k];
    for (std::size_t i = 0; i < canonical.size(); ++i)
      if (canonical[i] == joined) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace softdeca::stream
