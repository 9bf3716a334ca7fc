#include "bench_recording_memory.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdint>
#include <filesystem>

#include "recording/recording_index.h"
#include "recording/recording_writer.h"

namespace softdeca::cli {
namespace {
// Bytes allocated on the heap now (glibc); elsewhere 0, and the index's own count is used.
std::size_t heap_in_use() {
#if defined(__GLIBC__)
  return mallinfo2().uordblks;
#else
  return 0;
#endif
}
}  // namespace

RecordingMemory recording_memory_run(const std::string& path, std::size_t frames) {
  {
    recording::RecordingWriter w(path, recording::Header{});
    stream::Frame f;
    f.landmark_count = 149;
    for (std::size_t i = 0; i < frames; ++i) {
      f.capture_time = 10 + double(i) / 60;
      f.weights[i % f.weights.size()] = 0.5f;
      w.write(f);
    }
  }
  RecordingMemory out;
  out.frames = frames;
  out.file_bytes_per_frame = double(std::filesystem::file_size(path)) / double(frames);
  const std::size_t before = heap_in_use();
  const recording::RecordingIndex index = recording::RecordingIndex::open(path);
  const std::size_t after = heap_in_use();
  const std::size_t held = after > before ? after - before : index.memory_bytes();
  out.heap_bytes_per_frame = double(held) / double(index.frame_count());
  std::filesystem::remove(path);
  return out;
}

}  // namespace softdeca::cli
