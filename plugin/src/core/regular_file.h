// Opening a file the library reads or writes for its caller (recordings, CSV takes): only a
// regular file is accepted. The open itself never blocks (a FIFO with no other end would hold
// a plain open forever); the opened file is checked and refused when it is a FIFO, folder,
// device or socket, and only then switched back to blocking I/O (and, when writing, emptied).
// Every recording and take path goes through here: regular_file_posix.cpp, _windows.cpp.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

namespace softdeca {

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f) std::fclose(f);
  }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

enum class FileAccess {
  read,    // an existing file
  create,  // for writing: made, or emptied once known to be a regular file
};

// Throws softdeca::Error: SOFTDECA_ERROR_INVALID_ARGUMENT "<path> is a FIFO, not a regular
// file" (or a folder, a device, a socket), SOFTDECA_ERROR_IO when it cannot be opened.
FilePtr open_regular_file(const std::string& path, FileAccess access);

// The size in bytes of an open regular file.
std::uint64_t file_size(std::FILE* file);

// Exactly `n` bytes at `offset` (64-bit on every platform); false on an error or a short file.
bool read_at(std::FILE* file, std::uint64_t offset, void* data, std::size_t n);

}  // namespace softdeca
