// Writes a recording (recording_format.h): the header at creation, then one checksummed
// record per call, flushed to the operating system at once, so that a crash of the process
// loses nothing written and a crash of the machine or a full disk at most the last record.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "core/regular_file.h"
#include "recording/recording_format.h"

namespace softdeca::recording {

class RecordingWriter {
 public:
  // Creates (or replaces) the file and writes the header. Throws softdeca::Error; a path that
  // is not a regular file (a FIFO, a folder) is refused without blocking (core/regular_file.h).
  RecordingWriter(const std::string& path, const Header& header);
  // Writes into a stream the caller opened (`name` for messages): a pipe standing for a slow
  // disk in tests and benchmarks.
  RecordingWriter(FilePtr file, const std::string& name, const Header& header);
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  void write(const stream::Frame& frame);
  void write_profile(const stream::wire::Profile& profile);
  void write_neutral(const std::vector<float>& xyz);
  std::size_t frames_written() const { return frames_; }
  const std::string& path() const { return path_; }

 private:
  void write_header(const Header& header);
  void append_record(const std::vector<uint8_t>& payload);
  void put(const void* data, std::size_t size);

  std::string path_;
  FilePtr file_;
  std::vector<uint8_t> payload_;  // reused between records
  std::vector<uint8_t> record_;
  std::size_t frames_ = 0;
};

}  // namespace softdeca::recording
