// The walk over a recording's bytes shared by the whole-file reader (recording_reader.h) and the
// streaming index (recording_index.h): the header, then every good record in file order,
// recovering from damage by searching for the next record whose magic, length and checksum
// are good. The search is linear in the file: candidates' checksums come from prefix
// checksums, so no byte is checksummed more than once however many candidates overlap it
// (docs/security.md). Bytes come from a ByteSource, all in memory or a window onto a file, so
// walking a file holds at most a couple of records' worth of it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "recording/recording_format.h"
#include "stream/frame.h"

namespace softdeca::recording {

struct Recovery {
  std::size_t records = 0;           // good records read
  std::size_t damaged_regions = 0;   // stretches skipped to reach the next good record
  std::size_t skipped_bytes = 0;     // bytes in those stretches
  std::size_t truncated_bytes = 0;   // end of file after the last good record: a cut-off record
  std::size_t unknown_records = 0;   // good records of a type this version does not know
  std::size_t checksum_bytes = 0;    // bytes run through CRC-32: at most the file's size
  // Frames whose values break the frame rule (frame_rule.h): left out, or kept with their
  // weights clamped to [0, 1].
  std::size_t invalid_frames = 0;
  std::size_t clamped_frames = 0;
};

// What a recording says besides its frames.
struct RecordingMeta {
  Header header;
  std::vector<stream::wire::Profile> profiles;  // the header's, then any recorded later (the last 64)
  std::vector<float> neutral;                   // the last neutral mesh in the file, if any
  Recovery recovery;
};

// Bytes of a recording by offset.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  std::size_t size() const { return size_; }
  // [at, at + n), within size() and n at most kMaxSpan; valid until the next call. `at` is
  // never before the last release_before.
  virtual const uint8_t* bytes(std::size_t at, std::size_t n) = 0;
  // No bytes before `at` will be asked for again (a file's window may drop them).
  virtual void release_before(std::size_t) {}
  static constexpr std::size_t kMaxSpan = std::size_t{1} << 18;

 protected:
  std::size_t size_ = 0;
};

class MemorySource : public ByteSource {
 public:
  MemorySource(const uint8_t* data, std::size_t size) : data_(data) { size_ = size; }
  const uint8_t* bytes(std::size_t at, std::size_t) override { return data_ + at; }

 private:
  const uint8_t* data_;
};

// Reads the header into `meta` (its profile and neutral mesh too); `order` receives the stored
// weights' canonical indices. Returns the offset of the first record. Throws softdeca::Error
// (SOFTDECA_ERROR_FORMAT) when the header is missing, damaged or of another major version.
std::size_t read_header(ByteSource& source, RecordingMeta& meta, std::vector<int>& order);

// Every good record from `at` on, in file order: on_record(offset of the record, payload,
// payload length), the payload valid during the call. Fills the recovery counts.
void scan_records(ByteSource& source, std::size_t at, Recovery& recovery,
                  const std::function<void(std::size_t, const uint8_t*, std::size_t)>& on_record);

// A good record's payload: a profile or neutral mesh goes into `meta`; a frame is decoded
// into `frame` under the frame rule (frame_rule.h) and true returned when it is kept. Unknown
// types, bodies that do not parse and frames the rule refuses are counted in meta.recovery.
bool apply_record(const uint8_t* payload, std::size_t length, const std::vector<int>& order, RecordingMeta& meta,
                  stream::Frame& frame);

// A frame record's payload decoded under the frame rule, without counting: false when it
// does not parse or the rule refuses it.
bool decode_kept_frame(const uint8_t* payload, std::size_t length, const std::vector<int>& order,
                       stream::Frame& frame);

}  // namespace softdeca::recording
