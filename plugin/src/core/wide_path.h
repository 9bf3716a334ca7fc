// Windows only: the library's UTF-8 paths in the UTF-16 form the Win32 calls take.
#pragma once

#include <string>

namespace softdeca {

// Empty when `text` is empty or not valid UTF-8 (which then names no file).
std::wstring wide_path(const std::string& text);

}  // namespace softdeca
