#include "recording/recording_index.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <utility>

#include "core/error.h"
#include "recording/frame_rule.h"
#include "recording/record_codec.h"
#include "stream/byte_io.h"
#include "stream/crc32.h"

namespace softdeca::recording {
namespace {

// A window onto a file read front to back: it holds the bytes from the last release_before
// to the furthest asked for (a couple of records), never the file.
class FileSource : public ByteSource {
 public:
  FileSource(std::FILE* file, std::size_t size, const std::string& name) : file_(file), name_(name) { size_ = size; }

  void release_before(std::size_t at) override { released_ = std::max(released_, at); }

  const uint8_t* bytes(std::size_t at, std::size_t n) override {
    const std::size_t end = base_ + buffer_.size();
    if (at >= base_ && at + n <= end) return buffer_.data() + (at - base_);
    if (at < base_) throw Error(SOFTDECA_ERROR_INTERNAL, "recording reader asked for bytes it had released");
    const std::size_t keep = std::min({released_, at, end});
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(keep - base_));
    base_ = keep;
    const std::size_t want = std::min(size_, std::max(at + n, base_ + buffer_.size() + kReadAhead));
    const std::size_t have = base_ + buffer_.size();
    if (want > have) {
      buffer_.resize(want - base_);
      if (!read_at(file_, have, buffer_.data() + (have - base_), want - have))
        throw Error(SOFTDECA_ERROR_IO, "cannot read " + name_);
    }
    return buffer_.data() + (at - base_);
  }

 private:
  static constexpr std::size_t kReadAhead = std::size_t{1} << 16;
  std::FILE* file_;
  const std::string& name_;
  std::vector<uint8_t> buffer_;
  std::size_t base_ = 0;  // file offset of buffer_[0]
  std::size_t released_ = 0;
};

uint32_t load_u32(const uint8_t* p) {
  uint32_t v = 0;
  stream::ByteReader(p, 4).u32le(v);
  return v;
}

}  // namespace

RecordingIndex RecordingIndex::open(const std::string& path, const ReadLimits& limits) {
  RecordingIndex index;
  index.name_ = path;
  index.file_ = open_regular_file(path, FileAccess::read);
  // Unbuffered: the walk keeps its own window, and a frame read later must see the file as it
  // is then, not a stale stdio buffer.
  std::setvbuf(index.file_.get(), nullptr, _IONBF, 0);
  const std::uint64_t size = file_size(index.file_.get());
  require_within(path, size, limits, "a recording");
  FileSource source(index.file_.get(), static_cast<std::size_t>(size), index.name_);
  const std::size_t first = read_header(source, index.meta_, index.order_);
  stream::Frame frame;
  scan_records(source, first, index.meta_.recovery, [&](std::size_t at, const uint8_t* payload, std::size_t length) {
    if (apply_record(payload, length, index.order_, index.meta_, frame)) index.add(at, frame);
  });
  index.entries_.shrink_to_fit();
  return index;
}

RecordingIndex RecordingIndex::from_frames(RecordingMeta meta, const std::vector<stream::Frame>& frames) {
  RecordingIndex index;
  index.name_ = "frames in memory";
  index.meta_ = std::move(meta);
  for (std::size_t i = 0; i < stream::kBlendshapeCount; ++i) index.order_.push_back(static_cast<int>(i));
  std::vector<uint8_t> payload;
  for (const stream::Frame& f : frames) {
    stream::Frame kept = f;
    const FrameVerdict verdict = apply_frame_rule(kept);
    index.meta_.recovery.invalid_frames += verdict == FrameVerdict::refused;
    index.meta_.recovery.clamped_frames += verdict == FrameVerdict::clamped;
    if (verdict != FrameVerdict::refused) {
      encode_frame_record(kept, payload);
      const std::uint64_t at = index.memory_.size();
      stream::ByteWriter w(index.memory_);
      w.bytes(kRecordMagic.data(), kRecordMagic.size());
      w.u32le(static_cast<uint32_t>(payload.size()));
      w.u32le(stream::crc32(payload.data(), payload.size(), stream::crc32(index.memory_.data() + at + 4, 4)));
      w.bytes(payload.data(), payload.size());
      index.add(at, kept);
    }
  }
  return index;
}

void RecordingIndex::add(std::uint64_t offset, const stream::Frame& f) {
  entries_.push_back({offset, f.capture_time});
  tracked_ += f.tracking == stream::Tracking::tracked;
  with_landmarks_ += f.landmark_count > 0;
}

bool RecordingIndex::read(std::uint64_t offset, void* data, std::size_t n) const {
  if (!file_) {
    if (offset > memory_.size() || n > memory_.size() - offset) return false;
    std::memcpy(data, memory_.data() + offset, n);
    return true;
  }
  return read_at(file_.get(), offset, data, n);
}

stream::Frame RecordingIndex::frame(std::size_t i) const {
  const std::uint64_t at = entries_.at(i).offset;
  std::lock_guard<std::mutex> lock(*mutex_);
  record_.resize(kRecordHeaderBytes);
  bool ok = read(at, record_.data(), kRecordHeaderBytes) &&
            std::memcmp(record_.data(), kRecordMagic.data(), kRecordMagic.size()) == 0;
  const uint32_t length = ok ? load_u32(record_.data() + 4) : 0;
  ok = ok && length > 0 && length <= kMaxRecordBytes;
  if (ok) {
    record_.resize(kRecordHeaderBytes + length);
    ok = read(at + kRecordHeaderBytes, record_.data() + kRecordHeaderBytes, length) &&
         stream::crc32(record_.data() + kRecordHeaderBytes, length, stream::crc32(record_.data() + 4, 4)) ==
             load_u32(record_.data() + 8);
  }
  stream::Frame f;
  if (!ok || !decode_kept_frame(record_.data() + kRecordHeaderBytes, length, order_, f))
    throw Error(SOFTDECA_ERROR_IO, name_ + " changed while open: frame " + std::to_string(i) + " is gone");
  return f;
}

void RecordingIndex::sort_by_capture_time() {
  std::stable_sort(entries_.begin(), entries_.end(),
                   [](const Entry& a, const Entry& b) { return a.capture_time < b.capture_time; });
}

}  // namespace softdeca::recording
