// A recording written by a thread of its own: the receive path hands records over through a
// bounded queue and never waits for the disk. When the disk cannot keep up the queue fills,
// and further records are dropped and counted instead of stalling whoever polls frames.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "recording/recording_writer.h"

namespace softdeca::recording {

class BackgroundRecorder {
 public:
  // Takes over an open writer; `capacity` records may wait for the disk (at least 1).
  BackgroundRecorder(std::unique_ptr<RecordingWriter> writer, std::size_t capacity);
  ~BackgroundRecorder();  // finish()
  BackgroundRecorder(const BackgroundRecorder&) = delete;
  BackgroundRecorder& operator=(const BackgroundRecorder&) = delete;

  // Queue a record; false (and counted in dropped()) when the queue is full or writing failed.
  // Never waits for the disk.
  bool push(const stream::Frame& frame);
  bool push(const stream::wire::Profile& profile);
  bool push(const std::vector<float>& neutral_xyz);

  // Writes what is queued, stops the thread; returns the error that ended writing early, ""
  // if none. Idempotent.
  std::string finish();

  std::size_t frames_written() const { return frames_written_.load(); }
  std::size_t dropped() const { return dropped_.load(); }

 private:
  using Record = std::variant<stream::Frame, stream::wire::Profile, std::vector<float>>;
  bool enqueue(Record&& record);
  void run();

  std::unique_ptr<RecordingWriter> writer_;  // used by the thread only
  const std::size_t capacity_;
  std::mutex mutex_;  // queue_, stopping_, error_
  std::condition_variable wake_;
  std::deque<Record> queue_;
  bool stopping_ = false;
  bool failed_ = false;
  std::string error_;
  std::atomic<std::size_t> frames_written_{0};
  std::atomic<std::size_t> dropped_{0};
  std::thread thread_;
};

}  // namespace softdeca::recording
