#include "recording/record_scan.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "core/error.h"
#include "recording/frame_rule.h"
#include "recording/record_codec.h"
#include "stream/crc32.h"

namespace softdeca::recording {
namespace {
using stream::ByteReader;

constexpr std::size_t kFixedHeaderBytes = 8 + 2 + 2 + 4;  // magic, major, minor, field length
constexpr std::size_t kMaxProfilesKept = 64;              // a crafted file may hold millions
constexpr std::size_t kSearchChunk = std::size_t{1} << 16;

[[noreturn]] void bad(const std::string& why) {
  throw Error(SOFTDECA_ERROR_FORMAT, "not a readable recording: " + why);
}

uint32_t load_u32(const uint8_t* p) {
  uint32_t v = 0;
  ByteReader(p, 4).u32le(v);
  return v;
}

// CRC-32 of ranges in a window that only moves forward, from prefix checksums: each byte is
// checksummed once however many candidate records overlap it, so reading and resynchronising
// after damage stay linear in the file (a crafted file can put a candidate at every byte).
class PrefixCrc {
 public:
  explicit PrefixCrc(ByteSource& source) : source_(source), ring_(kWindow) {}

  // Prefixes count from here on: called at each candidate record, so that bytes between
  // candidates (damage with no record magic in it) are never checksummed or kept.
  void start_at(std::size_t at) {
    if (started_ && filled_ >= at) return;
    filled_ = at;
    ring_[at & kMask] = 0;
    started_ = true;
  }

  // crc32 of [a, b); a must not lie before the last start_at nor kWindow or more before the
  // furthest b so far (records are shorter).
  uint32_t range(std::size_t a, std::size_t b, std::size_t& checksum_bytes) {
    const uint32_t before = prefix(a, checksum_bytes);
    return stream::crc32_apply(shift(b - a), before) ^ prefix(b, checksum_bytes);
  }

  // crc32_shift(n) from a table filled on demand (n is at most a record's length): a crafted
  // file may give every candidate another length.
  uint32_t shift(std::size_t n) {
    if (shifts_.empty()) shifts_.push_back(stream::crc32_shift(0));
    while (shifts_.size() <= n) shifts_.push_back(stream::crc32_apply(shifts_.back(), stream::crc32_shift(1)));
    return shifts_[n];
  }

 private:
  static constexpr std::size_t kWindow = std::size_t{1} << 17;  // > a record's header and payload
  static constexpr std::size_t kMask = kWindow - 1;
  // crc32 from the last start to i.
  uint32_t prefix(std::size_t i, std::size_t& checksum_bytes) {
    if (i <= filled_) return ring_[i & kMask];
    checksum_bytes += i - filled_;
    const uint8_t* data = source_.bytes(filled_, i - filled_);
    for (std::size_t k = 0; filled_ < i; ++filled_, ++k)
      ring_[(filled_ + 1) & kMask] = stream::crc32(data + k, 1, ring_[filled_ & kMask]);
    return ring_[i & kMask];
  }
  ByteSource& source_;
  std::vector<uint32_t> ring_;
  std::vector<uint32_t> shifts_;
  std::size_t filled_ = 0;  // prefixes are known up to here
  bool started_ = false;
};

// Length of the good record at `at`, or 0 when its magic, length or checksum is wrong or the
// file ends before the length it declares. The checksum covers the length field too, so a
// corrupted length cannot pass.
std::size_t good_record(ByteSource& source, std::size_t at, PrefixCrc& window, std::size_t& checksum_bytes) {
  const std::size_t size = source.size();
  if (size - at < kRecordHeaderBytes) return 0;
  const uint8_t* head = source.bytes(at, kRecordHeaderBytes);
  if (std::memcmp(head, kRecordMagic.data(), kRecordMagic.size()) != 0) return 0;
  const uint32_t length = load_u32(head + 4), stored = load_u32(head + 8);
  if (length == 0 || length > kMaxRecordBytes || size - at - kRecordHeaderBytes < length) return 0;
  window.start_at(at + 4);
  const std::size_t payload = at + kRecordHeaderBytes;
  const uint32_t length_crc = window.range(at + 4, at + 8, checksum_bytes);  // first: the window moves forward
  const uint32_t payload_crc = window.range(payload, payload + length, checksum_bytes);
  const uint32_t crc = stream::crc32_apply(window.shift(length), length_crc) ^ payload_crc;
  return crc == stored ? kRecordHeaderBytes + length : 0;
}

// The next position from `from` that holds a good record, or size when there is none.
std::size_t next_good_record(ByteSource& source, std::size_t from, PrefixCrc& window, std::size_t& checksum_bytes) {
  const std::size_t size = source.size();
  for (std::size_t next = from; next + kRecordHeaderBytes <= size;) {
    source.release_before(next);
    const std::size_t n = std::min(kSearchChunk, size - next);
    const uint8_t* chunk = source.bytes(next, n);
    const void* hit = std::memchr(chunk, kRecordMagic[0], n);
    if (!hit) {
      next += n;
      continue;
    }
    next += static_cast<std::size_t>(static_cast<const uint8_t*>(hit) - chunk);
    if (next + kRecordHeaderBytes > size) break;
    if (good_record(source, next, window, checksum_bytes) > 0) return next;
    ++next;
  }
  return size;
}

void keep_profile(RecordingMeta& meta, stream::wire::Profile&& p) {
  meta.profiles.push_back(std::move(p));
  if (meta.profiles.size() > kMaxProfilesKept) meta.profiles.erase(meta.profiles.begin());
}

}  // namespace

std::size_t read_header(ByteSource& source, RecordingMeta& meta, std::vector<int>& order) {
  const std::size_t size = std::min(source.size(), kFixedHeaderBytes + kMaxHeaderBytes + 4);
  const uint8_t* data = source.bytes(0, size);
  if (size < kFixedHeaderBytes + 4 || std::memcmp(data, kFileMagic.data(), kFileMagic.size()) != 0)
    bad("no SDREC magic");
  ByteReader r(data + kFileMagic.size(), size - kFileMagic.size());
  uint16_t major = 0, minor = 0;
  uint32_t length = 0;
  r.u16le(major);
  r.u16le(minor);
  r.u32le(length);
  if (major != kVersionMajor)
    bad("format version " + std::to_string(major) + "." + std::to_string(minor) +
        " is not 1.x, which this reader understands");
  if (length > kMaxHeaderBytes || r.remaining() < std::size_t{length} + 4) bad("header cut short");
  ByteReader fields = r.sub(length);
  uint32_t stored = 0;
  r.u32le(stored);
  if (stream::crc32(data + kFileMagic.size(), 8 + std::size_t{length}) != stored) bad("header checksum mismatch");
  if (!decode_header_fields(fields, meta.header, order)) bad("malformed header fields");
  if (meta.header.has_profile) meta.profiles.push_back(meta.header.profile);
  meta.neutral = meta.header.neutral;
  return kFixedHeaderBytes + length + 4;
}

void scan_records(ByteSource& source, std::size_t at, Recovery& recovery,
                  const std::function<void(std::size_t, const uint8_t*, std::size_t)>& on_record) {
  const std::size_t size = source.size();
  PrefixCrc window(source);
  while (at < size) {
    source.release_before(at);
    const std::size_t n = good_record(source, at, window, recovery.checksum_bytes);
    if (n > 0) {
      on_record(at, source.bytes(at + kRecordHeaderBytes, n - kRecordHeaderBytes), n - kRecordHeaderBytes);
      ++recovery.records;
      at += n;
      continue;
    }
    // Damage: resume at the next good record, if any; with none, the rest is a cut-off tail.
    const std::size_t next = next_good_record(source, at + 1, window, recovery.checksum_bytes);
    if (next >= size) {
      recovery.truncated_bytes = size - at;
      break;
    }
    ++recovery.damaged_regions;
    recovery.skipped_bytes += next - at;
    at = next;
  }
}

bool decode_kept_frame(const uint8_t* payload, std::size_t length, const std::vector<int>& order,
                       stream::Frame& frame) {
  ByteReader r(payload, length);
  uint8_t type = 0;
  return r.u8(type) && type == static_cast<uint8_t>(RecordType::frame) && decode_frame_record(r, order, frame) &&
         apply_frame_rule(frame) != FrameVerdict::refused;
}

bool apply_record(const uint8_t* payload, std::size_t length, const std::vector<int>& order, RecordingMeta& meta,
                  stream::Frame& frame) {
  ByteReader r(payload, length);
  uint8_t type = 0;
  r.u8(type);
  bool ok = true;
  switch (static_cast<RecordType>(type)) {
    case RecordType::frame: {
      ok = decode_frame_record(r, order, frame);
      if (!ok) break;
      const FrameVerdict verdict = apply_frame_rule(frame);
      if (verdict == FrameVerdict::refused) {
        ++meta.recovery.invalid_frames;
        return false;
      }
      meta.recovery.clamped_frames += verdict == FrameVerdict::clamped;
      return true;
    }
    case RecordType::profile: {
      stream::wire::Profile p;
      ok = stream::wire::read_profile_body(r, p).reason == stream::DropReason::none;
      if (ok) keep_profile(meta, std::move(p));
      break;
    }
    case RecordType::neutral: {
      std::vector<float> xyz;
      ok = decode_neutral_body(r, xyz);
      if (ok) meta.neutral = std::move(xyz);
      break;
    }
    default:
      ++meta.recovery.unknown_records;
      return false;
  }
  // A record whose checksum holds but whose body does not parse was written by a broken writer.
  if (!ok) ++meta.recovery.damaged_regions;
  return false;
}

}  // namespace softdeca::recording
