// The platform-independent half of input_files.h: the rule for an avatar's own paths and the
// read of a file the user named (through core's one non-blocking, regular-file-only open).
#include "input_files.h"

#include <stdexcept>

#include "core/regular_file.h"

namespace softdeca::avatar_import {

std::vector<std::string> confined_steps(const std::string& relative) {
  const auto refuse = [&](const std::string& why) { throw std::runtime_error("'" + relative + "' " + why); };
  if (relative.empty()) refuse("is an empty path");
  if (relative.find('\0') != std::string::npos) refuse("holds a NUL character");
  if (relative.front() == '/') refuse("is an absolute path; an avatar names its files relative to its own folder");
  // Backslashes and colons are separators, drives or schemes on some platform: a path that is
  // relative everywhere has neither.
  if (relative.find('\\') != std::string::npos) refuse("holds a backslash; an avatar's paths use '/'");
  if (relative.find(':') != std::string::npos) refuse("names a drive or a scheme, not a file in the avatar's folder");
  std::vector<std::string> steps;
  std::size_t start = 0;
  while (start <= relative.size()) {
    std::size_t end = relative.find('/', start);
    if (end == std::string::npos) end = relative.size();
    const std::string step = relative.substr(start, end - start);
    if (step == "..") {
      if (steps.empty()) refuse("leads out of the avatar's folder");
      steps.pop_back();
    } else if (!step.empty() && step != ".") {
      steps.push_back(step);
    }
    start = end + 1;
  }
  if (steps.empty()) refuse("names the avatar's folder itself, not a file in it");
  return steps;
}

std::vector<std::string> folder_steps(const std::string& relative) {
  if (relative == ".") return {};
  return confined_steps(relative);
}

std::string read_named_file(const std::string& path, std::uint64_t max_bytes, const std::string& what) {
  FilePtr file;
  try {
    file = open_regular_file(path, FileAccess::read);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string(e.what()) + " (" + what + ")");
  }
  const std::uint64_t size = file_size(file.get());
  if (size == 0) throw std::runtime_error(path + " is empty (" + what + ")");
  if (size > max_bytes)
    throw std::runtime_error(path + ": " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) + " " +
                             what + " may have");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!read_at(file.get(), 0, bytes.data(), bytes.size())) throw std::runtime_error("cannot read " + path + " (it changed while read?)");
  return bytes;
}

}  // namespace softdeca::avatar_import
