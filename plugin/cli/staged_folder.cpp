#include "staged_folder.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#if defined(__linux__)
#include <fcntl.h>
#include <sys/syscall.h>
#endif

#include "core/atomic_write.h"

namespace softdeca::cli {

namespace fs = std::filesystem;

namespace {

constexpr int kNameAttempts = 100;
// Other writers may make, replace or remove DIR between a look at it and the rename: each time
// the rename is tried again, from a fresh look.
constexpr int kCommitAttempts = 100;
// renameat2's flags (linux/fs.h).
constexpr unsigned kNoReplace = 1u << 0, kExchange = 1u << 1;

[[noreturn]] void fail(const std::string& what, int error) {
  throw std::runtime_error(what + ": " + std::generic_category().message(error));
}

// renameat2(2): -1 with errno ENOSYS where the system has none, EINVAL where the file system
// does not support the flag.
int rename_with(const std::string& from, const std::string& to, unsigned flags) {
#if defined(__linux__) && defined(SYS_renameat2)
  return static_cast<int>(::syscall(SYS_renameat2, AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), flags));
#else
  (void)from, (void)to, (void)flags;
  errno = ENOSYS;
  return -1;
#endif
}

bool unsupported(int error) { return error == ENOSYS || error == EINVAL || error == ENOTSUP; }

// DIR as an absolute path without a trailing separator; a link to a folder, the folder it names.
fs::path folder_path(const std::string& dir) {
  std::error_code error;
  fs::path p = fs::absolute(fs::path(dir), error).lexically_normal();
  if (error) throw std::runtime_error("cannot find " + dir + ": " + error.message());
  if (!p.has_filename()) p = p.parent_path();
  if (fs::is_symlink(p, error)) {
    p = fs::canonical(p, error);
    if (error) throw std::runtime_error(dir + " is a link to nothing: give a folder");
  }
  if (p == p.root_path()) throw std::runtime_error("--out " + dir + " is the root folder: give a folder for the fit");
  return p;
}

}  // namespace

StagedFolder::StagedFolder(const std::string& dir, std::vector<std::string> replaceable)
    : replaceable_(std::move(replaceable)) {
  const fs::path p = folder_path(dir);
  dir_ = p.string();
  std::error_code error;
  fs::create_directories(p.parent_path(), error);
  if (error) throw std::runtime_error("cannot create " + p.parent_path().string() + ": " + error.message());
  const fs::file_status status = fs::symlink_status(p, error);
  if (fs::exists(status)) {
    if (!fs::is_directory(status)) throw std::runtime_error(dir_ + " is a file, not a folder: give a folder for the fit");
    check_replaceable(dir_);
  }
  for (int attempt = 0;; ++attempt) {
    temp_ = temporary_sibling(dir_, static_cast<unsigned long>(::getpid()));
    // Made here, now: a name someone else holds (a folder, a file, a link) is never used.
    if (fs::create_directory(temp_, error)) break;
    if (attempt == kNameAttempts || (error && error != std::errc::file_exists))
      throw std::runtime_error("cannot create a folder beside " + dir_ + ": " +
                               (error ? error.message() : std::string("every name tried is taken")));
  }
}

StagedFolder::~StagedFolder() {
  if (committed_) return;
  std::error_code error;
  fs::remove_all(temp_, error);  // removes links, never what they name
}

void StagedFolder::write(const std::string& name, const std::string& bytes) {
  // A new file beside `name` in the new folder, renamed over it: never opened through a link.
  write_file_atomically((fs::path(temp_) / name).string(), bytes.data(), bytes.size());
}

void StagedFolder::check_replaceable(const std::string& folder) const {
  std::error_code error;
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (std::find(replaceable_.begin(), replaceable_.end(), name) == replaceable_.end())
      throw std::runtime_error(dir_ + " holds " + name + ", which is not a fit folder's: give a new or empty folder, "
                               "or a fit folder to replace");
  }
  if (error) throw std::runtime_error("cannot read " + folder + ": " + error.message());
}

void StagedFolder::remove_previous(const std::string& previous) const {
  std::error_code error;
  for (const std::string& name : replaceable_) fs::remove(fs::path(previous) / name, error);
  fs::remove(previous, error);
  if (error)  // something came into it after it was looked at: left for its owner
    std::fprintf(stderr, "warning: the previous %s is left at %s: %s\n", dir_.c_str(), previous.c_str(), error.message().c_str());
}

void StagedFolder::commit() {
  if (committed_) return;
  for (int attempt = 0;; ++attempt) {
    const bool again = attempt < kCommitAttempts;
    std::error_code error;
    const fs::file_status status = fs::symlink_status(dir_, error);
    if (!fs::exists(status)) {
      if (rename_with(temp_, dir_, kNoReplace) == 0) break;
      if (errno == EEXIST && again) continue;  // another writer's folder came first: replace it
      if (!unsupported(errno)) fail("cannot move the new folder to " + dir_, errno);
      if (::rename(temp_.c_str(), dir_.c_str()) == 0) break;  // replaces at most an empty folder
      if ((errno == EEXIST || errno == ENOTEMPTY) && again) continue;
      fail("cannot move the new folder to " + dir_, errno);
    }
    if (!fs::is_directory(status)) throw std::runtime_error(dir_ + " is not a folder any more: nothing written");
    check_replaceable(dir_);
    if (rename_with(temp_, dir_, kExchange) == 0) {  // temp_ now names the previous folder
      committed_ = true;
      remove_previous(temp_);
      return;
    }
    if (errno == ENOENT && again) continue;  // DIR went meanwhile
    if (!unsupported(errno)) fail("cannot swap the new folder with " + dir_, errno);
    // No exchange on this file system: the previous folder renamed away, the new one renamed in.
    const std::string previous = temporary_sibling(dir_, static_cast<unsigned long>(::getpid()));
    if (::rename(dir_.c_str(), previous.c_str()) != 0) {
      if (errno == ENOENT && again) continue;
      fail("cannot move " + dir_ + " aside", errno);
    }
    if (::rename(temp_.c_str(), dir_.c_str()) == 0) {
      committed_ = true;
      remove_previous(previous);
      return;
    }
    const int moved = errno;
    if (::rename(previous.c_str(), dir_.c_str()) != 0) remove_previous(previous);  // another writer's folder is there now
    if ((moved == EEXIST || moved == ENOTEMPTY) && again) continue;
    fail("cannot move the new folder to " + dir_, moved);
  }
  committed_ = true;
}

}  // namespace softdeca::cli
