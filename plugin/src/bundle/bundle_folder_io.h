// What reading a bundle folder needs from the operating system: bundle_folder_io_posix.cpp
// (lstat, realpath, open with O_NOFOLLOW | O_NONBLOCK) or bundle_folder_io_windows.cpp
// (CreateFileW with FILE_FLAG_OPEN_REPARSE_POINT, GetFinalPathNameByHandleW, UTF-8 paths
// converted to UTF-16); the build compiles one of them. Paths are UTF-8 on every platform.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace softdeca::bundle {

enum class EntryKind { missing, regular, link, folder, fifo, device, socket, other };

// The kind of `path` itself (a final link is not followed), or of what it points to.
EntryKind entry_kind(const std::string& path);
EntryKind target_kind(const std::string& path);
// The absolute path with every link resolved; empty when it cannot be resolved.
std::string resolve_path(const std::string& path);
// `name` (relative, '/' separated) below the folder `root`, in the platform's own form.
std::string join_path(const std::string& root, const std::string& name);
// Whether the resolved `path` lies strictly below the resolved folder `root`.
bool path_inside(const std::string& root, const std::string& path);

// A file opened for reading without following a final link and without blocking (a FIFO,
// device or pipe opens at once and is then refused by is_regular, never read).
class ReadOnlyFile {
 public:
  explicit ReadOnlyFile(const std::string& path);
  ~ReadOnlyFile();
  ReadOnlyFile(const ReadOnlyFile&) = delete;
  ReadOnlyFile& operator=(const ReadOnlyFile&) = delete;

  bool is_open() const { return handle_ != kClosed; }
  // A regular file on disk (not a folder, link, FIFO, device or socket), with its size.
  bool is_regular() const;
  std::uint64_t size() const;
  // Exactly `n` bytes from the current position; false on an error or a short file.
  bool read(std::uint8_t* data, std::size_t n);

 private:
  static constexpr std::intptr_t kClosed = -1;
  std::intptr_t handle_ = kClosed;  // a file descriptor, or a Windows HANDLE
};

}  // namespace softdeca::bundle
