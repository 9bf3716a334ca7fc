// What the targets that read files need: a scratch folder of their own (one per process, so that
// parallel fuzzing jobs do not share it) and a write that can never block the harness itself.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace softdeca::fuzz {

// <temp>/softdeca-fuzz-<tag>-<pid>, made once.
inline std::filesystem::path workspace(const std::string& tag) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("softdeca-fuzz-" + tag + "-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

// No following links, no waiting for a FIFO's reader: what the last input left at `path`
// (a link, a FIFO) must not make the harness block or write elsewhere.
inline void write_file(const std::filesystem::path& path, const std::string& content) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0600);
  if (fd < 0) return;
  if (::write(fd, content.data(), content.size()) < 0) { /* a short file is fine */ }
  ::close(fd);
}

}  // namespace softdeca::fuzz
