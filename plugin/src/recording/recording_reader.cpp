#include "recording/recording_reader.h"

#include "recording/recording_index.h"

namespace softdeca::recording {

Recording parse_recording(const uint8_t* data, std::size_t size) {
  Recording rec;
  MemorySource source(data, size);
  std::vector<int> order;
  const std::size_t first = read_header(source, rec, order);
  stream::Frame frame;
  scan_records(source, first, rec.recovery, [&](std::size_t, const uint8_t* payload, std::size_t length) {
    if (apply_record(payload, length, order, rec, frame)) rec.frames.push_back(frame);
  });
  return rec;
}

Recording read_recording(const std::string& path, const ReadLimits& limits) {
  const RecordingIndex index = RecordingIndex::open(path, limits);
  Recording rec;
  static_cast<RecordingMeta&>(rec) = index.meta();
  rec.frames.reserve(index.frame_count());
  for (std::size_t i = 0; i < index.frame_count(); ++i) rec.frames.push_back(index.frame(i));
  return rec;
}

}  // namespace softdeca::recording
