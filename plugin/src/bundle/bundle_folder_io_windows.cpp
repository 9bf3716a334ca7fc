// Win32 behind bundle_folder_io.h. Paths are UTF-8 in the library and UTF-16 for the system.
// Links are symbolic links and junctions (name-surrogate reparse points); opening with
// FILE_FLAG_OPEN_REPARSE_POINT opens such an entry itself instead of its target.
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#ifndef NOMINMAX
#define NOMINMAX
#endif
#include <windows.h>

#include <vector>

#include "bundle/bundle_folder_io.h"
#include "core/wide_path.h"

namespace softdeca::bundle {

namespace {
std::string narrow(const wchar_t* text, std::size_t size) {
  if (size == 0 || size > 0x7fffffff) return {};
  const int n = WideCharToMultiByte(CP_UTF8, WC_ERR_INVALID_CHARS, text, static_cast<int>(size), nullptr, 0, nullptr, nullptr);
  if (n <= 0) return {};
  std::string out(static_cast<std::size_t>(n), '\0');
  WideCharToMultiByte(CP_UTF8, WC_ERR_INVALID_CHARS, text, static_cast<int>(size), out.data(), n, nullptr, nullptr);
  return out;
}

HANDLE native(std::intptr_t handle) { return reinterpret_cast<HANDLE>(handle); }

// Opens `path` for `access`; FILE_FLAG_BACKUP_SEMANTICS lets folders open too. Sharing
// everything: looking at a file never stands in the way of whoever else uses it.
HANDLE open_entry(const std::string& path, DWORD access, bool follow_links) {
  const std::wstring w = wide_path(path);
  if (w.empty()) return INVALID_HANDLE_VALUE;
  const DWORD flags = FILE_FLAG_BACKUP_SEMANTICS | (follow_links ? 0 : FILE_FLAG_OPEN_REPARSE_POINT);
  return CreateFileW(w.c_str(), access, FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE, nullptr,
                     OPEN_EXISTING, flags, nullptr);
}

// A FILE_TYPE_CHAR handle is a console or another device, FILE_TYPE_PIPE a pipe or socket.
EntryKind kind_of(HANDLE h) {
  switch (GetFileType(h)) {
    case FILE_TYPE_DISK: break;
    case FILE_TYPE_CHAR: return EntryKind::device;
    case FILE_TYPE_PIPE: return EntryKind::fifo;
    default: return EntryKind::other;
  }
  FILE_ATTRIBUTE_TAG_INFO info{};
  if (!GetFileInformationByHandleEx(h, FileAttributeTagInfo, &info, sizeof info)) return EntryKind::other;
  if ((info.FileAttributes & FILE_ATTRIBUTE_REPARSE_POINT) && IsReparseTagNameSurrogate(info.ReparseTag))
    return EntryKind::link;
  if (info.FileAttributes & FILE_ATTRIBUTE_DIRECTORY) return EntryKind::folder;
  return EntryKind::regular;
}

EntryKind kind_at(const std::string& path, bool follow_links) {
  const HANDLE h = open_entry(path, FILE_READ_ATTRIBUTES, follow_links);
  if (h == INVALID_HANDLE_VALUE) return EntryKind::missing;
  const EntryKind kind = kind_of(h);
  CloseHandle(h);
  return kind;
}
}  // namespace

EntryKind entry_kind(const std::string& path) { return kind_at(path, false); }

EntryKind target_kind(const std::string& path) { return kind_at(path, true); }

std::string resolve_path(const std::string& path) {
  const HANDLE h = open_entry(path, FILE_READ_ATTRIBUTES, true);
  if (h == INVALID_HANDLE_VALUE) return {};
  std::string out;
  // Devices (CON, NUL, ...) have no final path: they resolve to nothing.
  const DWORD flags = FILE_NAME_NORMALIZED | VOLUME_NAME_DOS;
  const DWORD need = GetFinalPathNameByHandleW(h, nullptr, 0, flags);
  if (need > 0) {
    std::vector<wchar_t> buffer(need + 1);
    const DWORD n = GetFinalPathNameByHandleW(h, buffer.data(), static_cast<DWORD>(buffer.size()), flags);
    if (n > 0 && n < buffer.size()) out = narrow(buffer.data(), n);
  }
  CloseHandle(h);
  return out;
}

// The resolved root is a \\?\ path, where the system takes no '/' for a separator.
std::string join_path(const std::string& root, const std::string& name) {
  std::string path = root + "\\" + name;
  for (std::size_t i = root.size(); i < path.size(); ++i)
    if (path[i] == '/') path[i] = '\\';
  return path;
}

// Both sides come from GetFinalPathNameByHandleW, which spells a file the same way each time.
bool path_inside(const std::string& root, const std::string& path) {
  return path.size() > root.size() + 1 && path.compare(0, root.size() + 1, root + "\\") == 0;
}

ReadOnlyFile::ReadOnlyFile(const std::string& path) {
  const std::wstring w = wide_path(path);
  if (w.empty()) return;
  // Without FILE_FLAG_BACKUP_SEMANTICS a folder does not open; a pipe or device opens without
  // waiting and is refused by is_regular before any read.
  const HANDLE h = CreateFileW(w.c_str(), GENERIC_READ, FILE_SHARE_READ, nullptr, OPEN_EXISTING,
                               FILE_FLAG_OPEN_REPARSE_POINT | FILE_FLAG_SEQUENTIAL_SCAN, nullptr);
  if (h != INVALID_HANDLE_VALUE) handle_ = reinterpret_cast<std::intptr_t>(h);
}

ReadOnlyFile::~ReadOnlyFile() {
  if (is_open()) CloseHandle(native(handle_));
}

bool ReadOnlyFile::is_regular() const { return is_open() && kind_of(native(handle_)) == EntryKind::regular; }

std::uint64_t ReadOnlyFile::size() const {
  LARGE_INTEGER size{};
  if (!is_open() || !GetFileSizeEx(native(handle_), &size) || size.QuadPart < 0) return 0;
  return static_cast<std::uint64_t>(size.QuadPart);
}

bool ReadOnlyFile::read(std::uint8_t* data, std::size_t n) {
  std::size_t got = 0;
  while (got < n) {
    const std::size_t left = n - got;
    const DWORD chunk = left > (DWORD{1} << 30) ? (DWORD{1} << 30) : static_cast<DWORD>(left);
    DWORD r = 0;
    if (!ReadFile(native(handle_), data + got, chunk, &r, nullptr) || r == 0) return false;
    got += r;
  }
  return true;
}

}  // namespace softdeca::bundle
