// bench-reliability's recording memory run: what an opened recording holds in memory per
// frame (recording/recording_index.h), measured on the heap.
#pragma once

#include <cstddef>
#include <string>

namespace softdeca::cli {

struct RecordingMemory {
  std::size_t frames = 0;
  double file_bytes_per_frame = 0;
  double heap_bytes_per_frame = 0;  // heap held by the open index, per frame
};

// Writes `frames` frames with 149 landmarks to `path`, opens it and measures; removes it.
RecordingMemory recording_memory_run(const std::string& path, std::size_t frames);

}  // namespace softdeca::cli
