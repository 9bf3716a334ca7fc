// Win32 behind regular_file.h: CreateFileW on the UTF-16 form of the UTF-8 path (folders open
// too, with FILE_FLAG_BACKUP_SEMANTICS, so that they can be named), GetFileType and the
// attributes to tell a file on disk from a pipe, console or folder, then a C stream on the handle.
#include <fcntl.h>
#include <io.h>
#include <windows.h>

#include "core/error.h"
#include "core/regular_file.h"
#include "core/wide_path.h"

namespace softdeca {
namespace {

// What the handle is when it is not a regular file, or nullptr.
const char* not_regular(HANDLE h) {
  switch (GetFileType(h)) {
    case FILE_TYPE_DISK: break;
    case FILE_TYPE_PIPE: return "a FIFO";
    case FILE_TYPE_CHAR: return "a device";
    default: return "not a regular file";
  }
  BY_HANDLE_FILE_INFORMATION info{};
  if (!GetFileInformationByHandle(h, &info)) return "not a regular file";
  if (info.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY) return "a folder";
  return nullptr;
}

}  // namespace

FilePtr open_regular_file(const std::string& path, FileAccess access) {
  const bool write = access == FileAccess::create;
  const std::wstring w = wide_path(path);
  const HANDLE h = w.empty() ? INVALID_HANDLE_VALUE
                             : CreateFileW(w.c_str(), write ? GENERIC_WRITE : GENERIC_READ,
                                           FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE, nullptr,
                                           write ? OPEN_ALWAYS : OPEN_EXISTING, FILE_FLAG_BACKUP_SEMANTICS, nullptr);
  if (h == INVALID_HANDLE_VALUE)
    throw Error(SOFTDECA_ERROR_IO, std::string(write ? "cannot create " : "cannot open ") + path);
  if (const char* kind = not_regular(h)) {
    CloseHandle(h);
    const std::string what(kind);
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT,
                path + " is " + what + (what == "not a regular file" ? "" : ", not a regular file"));
  }
  if (write && !SetEndOfFile(h)) {
    CloseHandle(h);
    throw Error(SOFTDECA_ERROR_IO, "cannot create " + path);
  }
  const int fd = _open_osfhandle(reinterpret_cast<intptr_t>(h), (write ? _O_WRONLY : _O_RDONLY) | _O_BINARY);
  if (fd < 0) {
    CloseHandle(h);
    throw Error(SOFTDECA_ERROR_IO, "cannot open " + path);
  }
  std::FILE* file = _fdopen(fd, write ? "wb" : "rb");
  if (!file) {
    _close(fd);
    throw Error(SOFTDECA_ERROR_IO, "cannot open " + path);
  }
  return FilePtr(file);
}

std::uint64_t file_size(std::FILE* file) {
  if (!file) return 0;
  const intptr_t handle = _get_osfhandle(_fileno(file));
  LARGE_INTEGER size{};
  if (handle == -1 || !GetFileSizeEx(reinterpret_cast<HANDLE>(handle), &size) || size.QuadPart < 0) return 0;
  return static_cast<std::uint64_t>(size.QuadPart);
}

bool read_at(std::FILE* file, std::uint64_t offset, void* data, std::size_t n) {
  if (!file || offset > static_cast<std::uint64_t>(INT64_MAX)) return false;
  return _fseeki64(file, static_cast<__int64>(offset), SEEK_SET) == 0 && std::fread(data, 1, n, file) == n;
}

}  // namespace softdeca
