// InputFolder on Windows: each step of a path is checked to be no reparse point (link or
// junction) before the file is opened through core's regular-file open. Unlike POSIX's
// descriptor-relative walk this checks before it opens, so a step swapped for a link between
// the two is a race a local attacker could win; docs/security.md says so.
#include <windows.h>

#include <stdexcept>

#include "core/regular_file.h"
#include "core/wide_path.h"
#include "input_files.h"

namespace softdeca::avatar_import {

struct InputFolder::Handle {};

namespace {
// Throws unless every step below `root` exists and is no reparse point; `folders` steps are
// folders, the rest (the last, when reading a file) a file.
void check_steps(const std::string& root, const std::vector<std::string>& steps, const std::string& shown) {
  std::string path = root;
  for (const std::string& step : steps) {
    path += "\\" + step;
    const DWORD attributes = GetFileAttributesW(wide_path(path).c_str());
    if (attributes == INVALID_FILE_ATTRIBUTES) throw std::runtime_error(shown + ": '" + step + "' does not exist");
    if (attributes & FILE_ATTRIBUTE_REPARSE_POINT)
      throw std::runtime_error(shown + ": '" + step + "' is a symbolic link or junction (links inside an avatar's folder are not followed)");
  }
}

std::string joined(const std::string& root, const std::vector<std::string>& steps) {
  std::string path = root;
  for (const std::string& step : steps) path += "\\" + step;
  return path;
}
}  // namespace

InputFolder::InputFolder(const std::string& dir) : path_(dir), handle_(std::make_unique<Handle>()) {
  const DWORD attributes = GetFileAttributesW(wide_path(dir).c_str());
  if (attributes == INVALID_FILE_ATTRIBUTES || !(attributes & FILE_ATTRIBUTE_DIRECTORY))
    throw std::runtime_error("cannot open the folder " + dir);
}

InputFolder::~InputFolder() = default;

std::string InputFolder::read(const std::string& relative, std::uint64_t max_bytes, const std::string& what) const {
  const std::string shown = path_ + "/" + relative;
  const std::vector<std::string> steps = confined_steps(relative);
  check_steps(path_, steps, shown);
  return read_named_file(joined(path_, steps), max_bytes, what);
}

bool InputFolder::has_folder(const std::string& relative) const {
  try {
    const std::vector<std::string> steps = folder_steps(relative);
    check_steps(path_, steps, relative);
    const DWORD attributes = GetFileAttributesW(wide_path(joined(path_, steps)).c_str());
    return attributes != INVALID_FILE_ATTRIBUTES && (attributes & FILE_ATTRIBUTE_DIRECTORY);
  } catch (const std::exception&) {
    return false;
  }
}

std::vector<std::string> InputFolder::list(const std::string& relative, std::size_t max_entries) const {
  const std::string shown = path_ + "/" + relative;
  const std::vector<std::string> steps = folder_steps(relative);
  check_steps(path_, steps, shown);
  WIN32_FIND_DATAW found;
  HANDLE search = FindFirstFileW(wide_path(joined(path_, steps) + "\\*").c_str(), &found);
  std::vector<std::string> names;
  if (search == INVALID_HANDLE_VALUE) return names;
  do {
    if (found.dwFileAttributes & (FILE_ATTRIBUTE_DIRECTORY | FILE_ATTRIBUTE_REPARSE_POINT)) continue;
    const int n = WideCharToMultiByte(CP_UTF8, 0, found.cFileName, -1, nullptr, 0, nullptr, nullptr);
    if (n <= 1) continue;
    std::string name(static_cast<std::size_t>(n - 1), '\0');
    WideCharToMultiByte(CP_UTF8, 0, found.cFileName, -1, name.data(), n, nullptr, nullptr);
    if (names.size() == max_entries) {
      FindClose(search);
      throw std::runtime_error(shown + ": more than " + std::to_string(max_entries) + " files");
    }
    names.push_back(std::move(name));
  } while (FindNextFileW(search, &found));
  FindClose(search);
  return names;
}

}  // namespace softdeca::avatar_import
