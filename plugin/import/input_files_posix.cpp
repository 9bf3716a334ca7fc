// InputFolder on POSIX: the folder is held open, and every step of a path is opened relative to
// the step before with O_NOFOLLOW, so no link is followed and nothing is resolved twice.
#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "input_files.h"

namespace softdeca::avatar_import {

namespace {
class Fd {
 public:
  explicit Fd(int fd = -1) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(Fd&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  Fd& operator=(Fd&& o) noexcept {
    std::swap(fd_, o.fd_);
    return *this;
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

int open_retrying(int dir, const char* name, int flags) {
  int fd = -1;
  do fd = ::openat(dir, name, flags | O_CLOEXEC | O_NOFOLLOW);
  while (fd < 0 && errno == EINTR);
  return fd;
}

const char* kind_of(mode_t mode) {
  if (S_ISFIFO(mode)) return "is a FIFO, not a regular file";
  if (S_ISDIR(mode)) return "is a folder, not a file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "is a device, not a regular file";
  if (S_ISSOCK(mode)) return "is a socket, not a regular file";
  if (S_ISLNK(mode)) return "is a symbolic link (links inside an avatar's folder are not followed)";
  return "is not a regular file";
}

// The reason an openat of `name` in `dir` failed, in the user's words.
std::string why_not(int dir, const std::string& name, int error) {
  struct stat st {};
  if (::fstatat(dir, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0) return kind_of(st.st_mode);
  if (error == ENOENT) return "does not exist";
  return std::string("cannot be opened: ") + std::strerror(error);
}

// The folder holding the last step, each step below `root` opened without following links.
Fd open_parent(int root, const std::vector<std::string>& steps, std::size_t count, const std::string& shown) {
  Fd dir(::dup(root));
  if (dir.get() < 0) throw std::runtime_error("cannot open " + shown + ": " + std::strerror(errno));
  for (std::size_t i = 0; i < count; ++i) {
    Fd next(open_retrying(dir.get(), steps[i].c_str(), O_RDONLY | O_DIRECTORY));
    if (next.get() < 0) {
      std::string step;
      for (std::size_t k = 0; k <= i; ++k) step += (k ? "/" : "") + steps[k];
      throw std::runtime_error(shown + ": '" + step + "' " + why_not(dir.get(), steps[i], errno));
    }
    dir = std::move(next);
  }
  return dir;
}
}  // namespace

struct InputFolder::Handle {
  Fd dir;
};

InputFolder::InputFolder(const std::string& dir) : path_(dir), handle_(std::make_unique<Handle>()) {
  int fd = -1;
  do fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  while (fd < 0 && errno == EINTR);
  if (fd < 0) throw std::runtime_error("cannot open the folder " + dir + ": " + std::strerror(errno));
  handle_->dir = Fd(fd);
}

InputFolder::~InputFolder() = default;

std::string InputFolder::read(const std::string& relative, std::uint64_t max_bytes, const std::string& what) const {
  const std::string shown = path_ + "/" + relative;
  const std::vector<std::string> steps = confined_steps(relative);
  const Fd dir = open_parent(handle_->dir.get(), steps, steps.size() - 1, shown);
  Fd file(open_retrying(dir.get(), steps.back().c_str(), O_RDONLY | O_NONBLOCK));
  if (file.get() < 0) throw std::runtime_error(shown + " " + why_not(dir.get(), steps.back(), errno) + " (" + what + ")");
  struct stat st {};
  if (::fstat(file.get(), &st) != 0) throw std::runtime_error("cannot read " + shown);
  if (!S_ISREG(st.st_mode)) throw std::runtime_error(shown + " " + kind_of(st.st_mode) + " (" + what + ")");
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size == 0) throw std::runtime_error(shown + " is empty (" + what + ")");
  if (size > max_bytes)
    throw std::runtime_error(shown + ": " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) + " " + what +
                             " may have");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pread(file.get(), bytes.data() + done, bytes.size() - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("cannot read " + shown + " (it changed while read?)");
    done += static_cast<std::size_t>(n);
  }
  return bytes;
}

bool InputFolder::has_folder(const std::string& relative) const {
  try {
    const std::vector<std::string> steps = folder_steps(relative);
    open_parent(handle_->dir.get(), steps, steps.size(), path_ + "/" + relative);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

std::vector<std::string> InputFolder::list(const std::string& relative, std::size_t max_entries) const {
  const std::string shown = path_ + "/" + relative;
  const std::vector<std::string> steps = folder_steps(relative);
  Fd dir = open_parent(handle_->dir.get(), steps, steps.size(), shown);
  const int listed = ::dup(dir.get());
  DIR* stream = listed < 0 ? nullptr : ::fdopendir(listed);
  if (!stream) {
    if (listed >= 0) ::close(listed);
    throw std::runtime_error("cannot list " + shown);
  }
  std::vector<std::string> names;
  while (const dirent* entry = ::readdir(stream)) {
    struct stat st {};
    if (::fstatat(dir.get(), entry->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode)) continue;
    if (names.size() == max_entries) {
      ::closedir(stream);
      throw std::runtime_error(shown + ": more than " + std::to_string(max_entries) + " files");
    }
    names.emplace_back(entry->d_name);
  }
  ::closedir(stream);
  return names;
}

}  // namespace softdeca::avatar_import
