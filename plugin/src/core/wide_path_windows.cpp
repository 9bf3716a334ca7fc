#include <windows.h>

#include "core/wide_path.h"

namespace softdeca {

std::wstring wide_path(const std::string& text) {
  if (text.empty() || text.size() > 0x7fffffff) return {};
  const int n = MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, text.data(), static_cast<int>(text.size()), nullptr, 0);
  if (n <= 0) return {};
  std::wstring out(static_cast<std::size_t>(n), L'\0');
  MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, text.data(), static_cast<int>(text.size()), out.data(), n);
  return out;
}

}  // namespace softdeca
