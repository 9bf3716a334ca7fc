#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>

#include "bundle/bundle_folder_io.h"

namespace softdeca::bundle {

namespace {
EntryKind kind_of(const struct stat& st) {
  if (S_ISREG(st.st_mode)) return EntryKind::regular;
  if (S_ISLNK(st.st_mode)) return EntryKind::link;
  if (S_ISDIR(st.st_mode)) return EntryKind::folder;
  if (S_ISFIFO(st.st_mode)) return EntryKind::fifo;
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) return EntryKind::device;
  if (S_ISSOCK(st.st_mode)) return EntryKind::socket;
  return EntryKind::other;
}
}  // namespace

EntryKind entry_kind(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 ? kind_of(st) : EntryKind::missing;
}

EntryKind target_kind(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? kind_of(st) : EntryKind::missing;
}

std::string resolve_path(const std::string& path) {
  char buffer[PATH_MAX];
  if (!::realpath(path.c_str(), buffer)) return {};
  return buffer;
}

std::string join_path(const std::string& root, const std::string& name) { return root + "/" + name; }

bool path_inside(const std::string& root, const std::string& path) {
  return path.compare(0, root.size() + 1, root + "/") == 0;
}

ReadOnlyFile::ReadOnlyFile(const std::string& path)
    : handle_(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC)) {}

ReadOnlyFile::~ReadOnlyFile() {
  if (is_open()) ::close(static_cast<int>(handle_));
}

bool ReadOnlyFile::is_regular() const {
  struct stat st {};
  return is_open() && ::fstat(static_cast<int>(handle_), &st) == 0 && S_ISREG(st.st_mode);
}

std::uint64_t ReadOnlyFile::size() const {
  struct stat st {};
  if (!is_open() || ::fstat(static_cast<int>(handle_), &st) != 0) return 0;
  return static_cast<std::uint64_t>(st.st_size);
}

bool ReadOnlyFile::read(std::uint8_t* data, std::size_t n) {
  std::size_t got = 0;
  while (got < n) {
    const ssize_t r = ::read(static_cast<int>(handle_), data + got, n - got);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    got += static_cast<std::size_t>(r);
  }
  return true;
}

}  // namespace softdeca::bundle
