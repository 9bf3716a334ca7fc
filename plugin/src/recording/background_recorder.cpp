#include "recording/background_recorder.h"

#include <utility>

namespace softdeca::recording {

BackgroundRecorder::BackgroundRecorder(std::unique_ptr<RecordingWriter> writer, std::size_t capacity)
    : writer_(std::move(writer)), capacity_(capacity < 1 ? 1 : capacity) {
  thread_ = std::thread([this] { run(); });
}

BackgroundRecorder::~BackgroundRecorder() { finish(); }

bool BackgroundRecorder::push(const stream::Frame& frame) { return enqueue(Record(frame)); }
bool BackgroundRecorder::push(const stream::wire::Profile& profile) { return enqueue(Record(profile)); }
bool BackgroundRecorder::push(const std::vector<float>& neutral_xyz) { return enqueue(Record(neutral_xyz)); }

bool BackgroundRecorder::enqueue(Record&& record) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_ || failed_ || queue_.size() >= capacity_) {
      ++dropped_;
      return false;
    }
    queue_.push_back(std::move(record));
  }
  wake_.notify_one();
  return true;
}

void BackgroundRecorder::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, all written
    Record record = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    std::string error;
    try {
      if (const auto* f = std::get_if<stream::Frame>(&record)) {
        writer_->write(*f);
        ++frames_written_;
      } else if (const auto* p = std::get_if<stream::wire::Profile>(&record)) {
        writer_->write_profile(*p);
      } else {
        writer_->write_neutral(std::get<std::vector<float>>(record));
      }
    } catch (const std::exception& e) {  // a full disk ends the recording, not the stream
      error = e.what();
    }
    lock.lock();
    if (!error.empty()) {
      failed_ = true;
      error_ = error;
      dropped_ += queue_.size();
      queue_.clear();
    }
  }
}

std::string BackgroundRecorder::finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  writer_.reset();  // closes the file
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

}  // namespace softdeca::recording
