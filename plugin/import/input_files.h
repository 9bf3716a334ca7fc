// How the import reads files: each file is opened once, as a regular file, without blocking (a
// FIFO with no writer would hold a plain open forever) and checked on the open descriptor (no
// check-then-open race), then read whole within a size bound. A file named by the user is opened
// as named; a file an avatar names itself (a glTF buffer's URI, an avatar folder's members) is
// resolved inside the avatar's folder only: no absolute path, no "..", no symbolic link at any
// step (a link cannot lead out of the folder, whatever it points to).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace softdeca::avatar_import {

// The bytes of a file the user named (the avatar, a names file). Throws std::runtime_error:
// "<path> is a FIFO, not a regular file", "<path>: N bytes, more than the M ...", "cannot read".
std::string read_named_file(const std::string& path, std::uint64_t max_bytes, const std::string& what);

// A folder whose files an avatar may name: every path is relative to it and stays in it.
class InputFolder {
 public:
  // `dir` as the user named it (a link the user gave is theirs to give; links below are not).
  explicit InputFolder(const std::string& dir);
  ~InputFolder();
  InputFolder(const InputFolder&) = delete;
  InputFolder& operator=(const InputFolder&) = delete;

  const std::string& path() const { return path_; }
  // The bytes of `relative` (forward slashes), within `max_bytes`. Throws, naming the path and
  // the reason: "leads out of the avatar's folder", "is a symbolic link", "is a FIFO, not a
  // regular file", "does not exist", "more than N bytes".
  std::string read(const std::string& relative, std::uint64_t max_bytes, const std::string& what) const;
  // Whether `relative` is a folder in it (not through a link); "." is the folder itself.
  bool has_folder(const std::string& relative) const;
  // The names of the regular entries of folder `relative` (not through a link), at most
  // `max_entries` (more throws).
  std::vector<std::string> list(const std::string& relative, std::size_t max_entries) const;

 private:
  std::string path_;
  struct Handle;
  std::unique_ptr<Handle> handle_;
};

// `relative` split into its steps, "." dropped; throws when it is absolute, empty, names a
// drive or a scheme, or climbs out with "..". Pure: the rule both platforms share.
std::vector<std::string> confined_steps(const std::string& relative);
// The same for a folder, where "." (no steps) names the avatar's folder itself.
std::vector<std::string> folder_steps(const std::string& relative);

}  // namespace softdeca::avatar_import
