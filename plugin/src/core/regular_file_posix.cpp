#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <limits>

#include "core/error.h"
#include "core/regular_file.h"

namespace softdeca {
namespace {

const char* kind_name(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

[[noreturn]] void refuse(const std::string& path, mode_t mode) {
  const char* kind = kind_name(mode);
  throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT,
              path + " is " + kind + (std::strcmp(kind, "not a regular file") == 0 ? "" : ", not a regular file"));
}

}  // namespace

FilePtr open_regular_file(const std::string& path, FileAccess access) {
  const bool write = access == FileAccess::create;
  // O_NONBLOCK: a FIFO opens (or fails with ENXIO) at once instead of waiting for its other end.
  const int flags = (write ? O_WRONLY | O_CREAT : O_RDONLY) | O_NONBLOCK | O_CLOEXEC;
  int fd = -1;
  do fd = ::open(path.c_str(), flags, 0666);
  while (fd < 0 && errno == EINTR);
  if (fd < 0) {
    const int error = errno;
    struct stat st {};
    // A folder opened for writing (EISDIR), a FIFO without a reader (ENXIO): name what it is.
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) refuse(path, st.st_mode);
    throw Error(SOFTDECA_ERROR_IO, std::string(write ? "cannot create " : "cannot open ") + path + ": " +
                                       std::strerror(error));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    refuse(path, st.st_mode);
  }
  const int status = ::fcntl(fd, F_GETFL);
  if (status < 0 || ::fcntl(fd, F_SETFL, status & ~O_NONBLOCK) != 0 || (write && ::ftruncate(fd, 0) != 0)) {
    const int error = errno;
    ::close(fd);
    throw Error(SOFTDECA_ERROR_IO, "cannot open " + path + ": " + std::strerror(error));
  }
  std::FILE* file = ::fdopen(fd, write ? "wb" : "rb");
  if (!file) {
    ::close(fd);
    throw Error(SOFTDECA_ERROR_IO, "cannot open " + path);
  }
  return FilePtr(file);
}

std::uint64_t file_size(std::FILE* file) {
  struct stat st {};
  if (!file || ::fstat(::fileno(file), &st) != 0 || st.st_size < 0) return 0;
  return static_cast<std::uint64_t>(st.st_size);
}

bool read_at(std::FILE* file, std::uint64_t offset, void* data, std::size_t n) {
  if (!file || offset > static_cast<std::uint64_t>(std::numeric_limits<off_t>::max())) return false;
  return ::fseeko(file, static_cast<off_t>(offset), SEEK_SET) == 0 && std::fread(data, 1, n, file) == n;
}

}  // namespace softdeca
