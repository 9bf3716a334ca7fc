// POSIX behind atomic_write.h: open(O_CREAT | O_EXCL | O_NOFOLLOW) of a unique sibling, write,
// fsync, rename(2) over the path (atomic within a file system), then fsync of the folder so the
// rename itself survives a power cut.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include "core/atomic_write.h"
#include "core/error.h"

namespace softdeca {
namespace {

constexpr int kNameAttempts = 100;

[[noreturn]] void fail(const std::string& path, int error) {
  throw Error(SOFTDECA_ERROR_IO, "could not save " + path + ": " + std::generic_category().message(error));
}

bool write_all(int fd, const void* data, std::size_t size) {
  const auto* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      return false;
    }
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// Best effort: the rename is already visible; this makes it durable.
void sync_folder_of(const std::string& path) {
  const std::string::size_type slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void write_file_atomically(const std::string& path, const void* data, std::size_t size) {
  std::string temp;
  int fd = -1;
  for (int attempt = 0; fd < 0; ++attempt) {
    temp = temporary_sibling(path, static_cast<unsigned long>(::getpid()));
    fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0 && !((errno == EEXIST || errno == EINTR) && attempt < kNameAttempts)) fail(path, errno);
  }
  bool written = write_all(fd, data, size) && ::fsync(fd) == 0;
  int error = errno;
  if (::close(fd) != 0 && written) written = false, error = errno;
  if (written && ::rename(temp.c_str(), path.c_str()) == 0) {
    sync_folder_of(path);
    return;
  }
  if (written) error = errno;
  ::unlink(temp.c_str());
  fail(path, error);
}

}  // namespace softdeca
