// Win32 behind atomic_write.h: CreateFileW(CREATE_NEW) of a unique sibling (never opens what is
// there, a link included), WriteFile, FlushFileBuffers, then MoveFileExW with
// MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH over the path. A replacement fails while
// another process holds the old file open without sharing its deletion (or replaces it at the
// same moment): it is retried for a while before giving up.
#include <windows.h>

#include "core/atomic_write.h"
#include "core/error.h"
#include "core/wide_path.h"

namespace softdeca {
namespace {

constexpr int kNameAttempts = 100;
constexpr int kMoveAttempts = 200;  // 10 ms apart
constexpr std::size_t kChunk = std::size_t{1} << 30;

std::string reason(DWORD error) {
  switch (error) {
    case ERROR_ACCESS_DENIED: return "access is denied";
    case ERROR_SHARING_VIOLATION: return "another program holds it open";
    case ERROR_PATH_NOT_FOUND: return "its folder does not exist";
    case ERROR_DISK_FULL:
    case ERROR_HANDLE_DISK_FULL: return "the disk is full";
    case ERROR_WRITE_PROTECT: return "the disk is write-protected";
    default: return "Windows error " + std::to_string(error);
  }
}

[[noreturn]] void fail(const std::string& path, DWORD error) {
  throw Error(SOFTDECA_ERROR_IO, "could not save " + path + ": " + reason(error));
}

bool write_all(HANDLE h, const void* data, std::size_t size) {
  const auto* p = static_cast<const char*>(data);
  while (size > 0) {
    const DWORD chunk = static_cast<DWORD>(size < kChunk ? size : kChunk);
    DWORD written = 0;
    if (!WriteFile(h, p, chunk, &written, nullptr) || written == 0) return false;
    p += written;
    size -= written;
  }
  return true;
}

}  // namespace

void write_file_atomically(const std::string& path, const void* data, std::size_t size) {
  const std::wstring target = wide_path(path);
  if (target.empty()) fail(path, ERROR_INVALID_NAME);
  std::wstring temp;
  HANDLE h = INVALID_HANDLE_VALUE;
  for (int attempt = 0; h == INVALID_HANDLE_VALUE; ++attempt) {
    temp = wide_path(temporary_sibling(path, static_cast<unsigned long>(GetCurrentProcessId())));
    h = CreateFileW(temp.c_str(), GENERIC_WRITE, 0, nullptr, CREATE_NEW, FILE_ATTRIBUTE_NORMAL, nullptr);
    const DWORD error = GetLastError();
    if (h == INVALID_HANDLE_VALUE && !((error == ERROR_FILE_EXISTS || error == ERROR_ALREADY_EXISTS) && attempt < kNameAttempts))
      fail(path, error);
  }
  bool written = write_all(h, data, size) && FlushFileBuffers(h);
  DWORD error = written ? ERROR_SUCCESS : GetLastError();
  if (!CloseHandle(h) && written) written = false, error = GetLastError();
  for (int attempt = 0; written; ++attempt) {
    if (MoveFileExW(temp.c_str(), target.c_str(), MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH)) return;
    error = GetLastError();
    if (!((error == ERROR_ACCESS_DENIED || error == ERROR_SHARING_VIOLATION) && attempt < kMoveAttempts)) break;
    Sleep(10);
  }
  DeleteFileW(temp.c_str());
  fail(path, error);
}

}  // namespace softdeca
