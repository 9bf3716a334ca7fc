// Writing a whole file so that a reader, another thread or another process sees the previous
// file or the new one, never a part of either: the bytes go to a new file of a unique name in the
// same folder (created exclusively, so never through a link someone left there), are flushed to
// disk, and that file is renamed over the path (POSIX rename; Windows MoveFileExW with
// MOVEFILE_REPLACE_EXISTING). On any failure the temporary file is removed and the previous
// file is left as it was. atomic_write_posix.cpp, atomic_write_windows.cpp.
#pragma once

#include <cstddef>
#include <string>

namespace softdeca {

// Throws Error(SOFTDECA_ERROR_IO) "could not save <path>: <reason>".
void write_file_atomically(const std::string& path, const void* data, std::size_t size);

// A name for a temporary sibling of `path` (same folder, hidden, unique to this process and
// call: ".<name>.<process>-<count>-<clock>.tmp"; `path` does not end in a separator), for a file
// or folder created exclusively and renamed over `path`. Another's name may still clash: create
// it exclusively and retry with a new name.
std::string temporary_sibling(const std::string& path, unsigned long process_id);

}  // namespace softdeca
