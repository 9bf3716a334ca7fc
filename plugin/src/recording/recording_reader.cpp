#include "recording/recording_reader.h"

#include <cstring>

#include "core/error.h"
#include "core/regular_file.h"
#include "recording/frame_rule.h"
#include "recording/record_codec.h"
#include "stream/crc32.h"

namespace softdeca::recording {
namespace {
using stream::ByteReader;

constexpr std::size_t kFixedHeaderBytes = 8 + 2 + 2 + 4;  // magic, major, minor, field length

[[noreturn]] void bad(const std::string& why) {
  throw Error(SOFTDECA_ERROR_FORMAT, "not a readable recording: " + why);
}

uint32_t load_u32(const uint8_t* p) {
  uint32_t v = 0;
  ByteReader(p, 4).u32le(v);
  return v;
}

// The record framing at `at` (magic, a length the file holds), or 0: the payload length.
std::size_t framed_length(const uint8_t* data, std::size_t size, std::size_t at) {
  if (size - at < kRecordHeaderBytes) return 0;
  if (std::memcmp(data + at, kRecordMagic.data(), kRecordMagic.size()) != 0) return 0;
  const uint32_t length = load_u32(data + at + 4);
  if (length == 0 || length > kMaxRecordBytes) return 0;
  if (size - at - kRecordHeaderBytes < length) return 0;
  return length;
}

// CRC-32 of ranges in a window that only moves forward, from prefix checksums: each byte is
// checksummed once however many candidate records overlap it, so reading and resynchronising
// after damage stay linear in the file (a crafted file can put a candidate at every byte).
class PrefixCrc {
 public:
  explicit PrefixCrc(const uint8_t* data) : data_(data), ring_(kWindow) {}

  // crc32 of [a, b); a must not lie before the first call's a nor kWindow or more before the
  // furthest b so far (records are shorter).
  uint32_t range(std::size_t a, std::size_t b, std::size_t& checksum_bytes) {
    if (!started_) {  // prefixes count from the first byte asked for; later calls never ask before it
      filled_ = a;
      ring_[a & kMask] = 0;
      started_ = true;
    }
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
  // crc32 from the first call's a to i.
  uint32_t prefix(std::size_t i, std::size_t& checksum_bytes) {
    if (i <= filled_) return ring_[i & kMask];
    checksum_bytes += i - filled_;
    for (; filled_ < i; ++filled_) ring_[(filled_ + 1) & kMask] = stream::crc32(data_ + filled_, 1, ring_[filled_ & kMask]);
    return ring_[i & kMask];
  }
  const uint8_t* data_;
  std::vector<uint32_t> ring_;
  std::vector<uint32_t> shifts_;
  std::size_t filled_ = 0;  // prefixes are known up to here
  bool started_ = false;
};

// Length of the good record at `at`, or 0 when its magic, length or checksum is wrong or
// the file ends before the length it declares. The checksum covers the length field too, so
// a corrupted length cannot pass.
std::size_t good_record(const uint8_t* data, std::size_t size, std::size_t at, PrefixCrc& window,
                        std::size_t& checksum_bytes) {
  const std::size_t length = framed_length(data, size, at);
  if (length == 0) return 0;
  const std::size_t payload = at + kRecordHeaderBytes;
  const uint32_t length_crc = window.range(at + 4, at + 8, checksum_bytes);  // first: the window moves forward
  const uint32_t payload_crc = window.range(payload, payload + length, checksum_bytes);
  const uint32_t crc = stream::crc32_apply(window.shift(length), length_crc) ^ payload_crc;
  return crc == load_u32(data + at + 8) ? kRecordHeaderBytes + length : 0;
}

void read_header(const uint8_t* data, std::size_t size, Recording& rec, std::vector<int>& order,
                 std::size_t& end) {
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
  if (!decode_header_fields(fields, rec.header, order)) bad("malformed header fields");
  if (rec.header.has_profile) rec.profiles.push_back(rec.header.profile);
  rec.neutral = rec.header.neutral;
  end = kFixedHeaderBytes + length + 4;
}

void apply_record(const uint8_t* payload, std::size_t length, const std::vector<int>& order,
                  Recording& rec) {
  ByteReader r(payload, length);
  uint8_t type = 0;
  r.u8(type);
  bool ok = true;
  switch (static_cast<RecordType>(type)) {
    case RecordType::frame: {
      stream::Frame f;
      ok = decode_frame_record(r, order, f);
      if (!ok) break;
      const FrameVerdict verdict = apply_frame_rule(f);
      if (verdict == FrameVerdict::refused) {
        ++rec.recovery.invalid_frames;
        break;
      }
      rec.recovery.clamped_frames += verdict == FrameVerdict::clamped;
      rec.frames.push_back(f);
      break;
    }
    case RecordType::profile: {
      stream::wire::Profile p;
      ok = stream::wire::read_profile_body(r, p).reason == stream::DropReason::none;
      if (ok) rec.profiles.push_back(std::move(p));
      break;
    }
    case RecordType::neutral: {
      std::vector<float> xyz;
      ok = decode_neutral_body(r, xyz);
      if (ok) rec.neutral = std::move(xyz);
      break;
    }
    default:
      ++rec.recovery.unknown_records;
      return;
  }
  // A record whose checksum holds but whose body does not parse was written by a broken writer.
  if (!ok) ++rec.recovery.damaged_regions;
}

}  // namespace

Recording parse_recording(const uint8_t* data, std::size_t size) {
  Recording rec;
  std::vector<int> order;
  std::size_t at = 0;
  read_header(data, size, rec, order, at);
  std::size_t& checksum_bytes = rec.recovery.checksum_bytes;
  PrefixCrc window(data);
  while (at < size) {
    const std::size_t n = good_record(data, size, at, window, checksum_bytes);
    if (n > 0) {
      apply_record(data + at + kRecordHeaderBytes, n - kRecordHeaderBytes, order, rec);
      ++rec.recovery.records;
      at += n;
      continue;
    }
    // Damage: resume at the next good record, if any; with none, the rest is a cut-off tail.
    std::size_t next = at + 1;
    bool found = false;
    for (; next + kRecordHeaderBytes <= size; ++next) {
      if (data[next] != kRecordMagic[0]) continue;
      if (good_record(data, size, next, window, checksum_bytes) > 0) {
        found = true;
        break;
      }
    }
    if (!found) {
      rec.recovery.truncated_bytes = size - at;
      break;
    }
    ++rec.recovery.damaged_regions;
    rec.recovery.skipped_bytes += next - at;
    at = next;
  }
  return rec;
}

Recording read_recording(const std::string& path) {
  const FilePtr file = open_regular_file(path, FileAccess::read);
  std::vector<uint8_t> bytes(static_cast<std::size_t>(file_size(file.get())));
  if (std::fread(bytes.data(), 1, bytes.size(), file.get()) != bytes.size())
    throw Error(SOFTDECA_ERROR_IO, "cannot read " + path);
  return parse_recording(bytes.data(), bytes.size());
}

}  // namespace softdeca::recording
