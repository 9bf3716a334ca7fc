// A recording opened without reading it into memory: one pass over the file builds an index
// of its frames (16 bytes each: where the record starts and its capture time) and keeps what
// the file says besides frames (header, profiles, neutral mesh, recovery counts); frames are
// decoded on demand. Memory is bounded by the frame count, not by the file's size, and a size
// cap keeps a crafted file (a terabyte of sparse zeros) from taking the pass forever.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/regular_file.h"
#include "recording/read_limits.h"
#include "recording/record_scan.h"

namespace softdeca::recording {

class RecordingIndex {
 public:
  // Throws softdeca::Error: INVALID_ARGUMENT when `path` is not a regular file (a FIFO, a
  // folder), FORMAT when the file is over limits.max_bytes or its header is unreadable, IO
  // when it cannot be read.
  static RecordingIndex open(const std::string& path, const ReadLimits& limits = {});
  // Frames already in memory (tests, fuzzing), held as the records a file would hold.
  static RecordingIndex from_frames(RecordingMeta meta, const std::vector<stream::Frame>& frames);

  const RecordingMeta& meta() const { return meta_; }
  std::size_t frame_count() const { return entries_.size(); }
  double capture_time(std::size_t i) const { return entries_.at(i).capture_time; }
  // Frame i (file order until sort_by_capture_time), decoded and under the frame rule.
  // Throws softdeca::Error (IO) when the file no longer holds it.
  stream::Frame frame(std::size_t i) const;
  void sort_by_capture_time();  // stable: recorders write in capture order, hand-made files may not

  std::size_t tracked_frames() const { return tracked_; }
  std::size_t frames_with_landmarks() const { return with_landmarks_; }
  // Bytes this index holds for its frames (the entries), to show it is bounded by the count.
  std::size_t memory_bytes() const { return entries_.capacity() * sizeof(Entry); }

 private:
  struct Entry {
    std::uint64_t offset;  // of the record in the file (or in memory_)
    double capture_time;
  };
  RecordingIndex() : mutex_(std::make_unique<std::mutex>()) {}
  void add(std::uint64_t offset, const stream::Frame& frame);
  bool read(std::uint64_t offset, void* data, std::size_t n) const;

  std::string name_;                 // for messages
  FilePtr file_;                     // or, for frames in memory:
  std::vector<uint8_t> memory_;
  RecordingMeta meta_;
  std::vector<int> order_;           // stored weights' canonical indices
  std::vector<Entry> entries_;
  std::size_t tracked_ = 0, with_landmarks_ = 0;
  std::unique_ptr<std::mutex> mutex_;  // frame() reads through one FILE from any thread
  mutable std::vector<uint8_t> record_;
};

}  // namespace softdeca::recording
