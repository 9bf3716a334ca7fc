// Recovering a damaged recording costs time linear in the file, however the damage is crafted:
// checked by counting the bytes run through CRC-32, not by a clock (timings: make bench).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "recording/recording_format.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "stream/crc32.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::recording;

TEST(Crc32, CombineMatchesTheChecksumOfTheConcatenation) {
  std::mt19937 rng(3);
  std::vector<uint8_t> data(100000);
  for (auto& b : data) b = static_cast<uint8_t>(rng());
  for (const std::size_t split : {0u, 1u, 7u, 4096u, 65536u, 99999u, 100000u}) {
    const uint32_t a = stream::crc32(data.data(), split);
    const uint32_t b = stream::crc32(data.data() + split, data.size() - split);
    EXPECT_EQ(stream::crc32_combine(a, b, data.size() - split), stream::crc32(data.data(), data.size())) << split;
  }
}

namespace {
// A good recording of `frames` frames, as bytes.
std::vector<uint8_t> good_recording(const std::string& name, int frames) {
  const std::string path = test::temp_path(name);
  {
    RecordingWriter w(path, Header{});
    for (int i = 0; i < frames; ++i) w.write(test::make_frame(static_cast<uint32_t>(i)));
  }
  std::vector<uint8_t> bytes = test::read_bytes(path);
  std::remove(path.c_str());
  return bytes;
}
}  // namespace

// 4 MiB of record headers that each claim the largest payload (64 KiB) with a wrong checksum:
// a candidate every 12 bytes. Read naively, every candidate costs a 64 KiB checksum.
TEST(RecordingResync, CraftedDamageIsScannedInLinearTime) {
  const std::vector<uint8_t> head = good_recording("resync-head.sdrec", 3);
  std::vector<uint8_t> bytes = head;
  const std::size_t crafted = std::size_t{4} << 20;
  const uint8_t candidate[12] = {'S', 'D', 'R', 'C', 0x00, 0x00, 0x01, 0x00, 0xEF, 0xBE, 0xAD, 0xDE};
  while (bytes.size() < head.size() + crafted) bytes.insert(bytes.end(), candidate, candidate + 12);
  // Two good records after the damage (the head's last two, copied): they must be found.
  const std::size_t record_bytes = (head.size() - good_recording("resync-empty.sdrec", 0).size()) / 3;
  bytes.insert(bytes.end(), head.end() - 2 * static_cast<std::ptrdiff_t>(record_bytes), head.end());

  const Recording rec = parse_recording(bytes.data(), bytes.size());
  EXPECT_EQ(rec.frames.size(), 5u);  // 3 before the damage, 2 after
  EXPECT_EQ(rec.recovery.damaged_regions, 1u);
  EXPECT_GE(rec.recovery.skipped_bytes, crafted);
  // Linear: no byte is checksummed twice (the naive search checksums ~5,000x the file).
  EXPECT_LE(rec.recovery.checksum_bytes, bytes.size());
  EXPECT_GT(rec.recovery.checksum_bytes, crafted / 2);  // the counter counts
}

// Damage after every good record: each resynchronisation starts where the last one left off.
TEST(RecordingResync, RepeatedDamageStaysLinear) {
  const std::vector<uint8_t> empty = good_recording("resync-empty2.sdrec", 0);
  const std::vector<uint8_t> one = good_recording("resync-one.sdrec", 1);
  const std::vector<uint8_t> record(one.begin() + static_cast<std::ptrdiff_t>(empty.size()), one.end());
  std::vector<uint8_t> bytes = empty;
  const uint8_t candidate[12] = {'S', 'D', 'R', 'C', 0x00, 0x00, 0x01, 0x00, 0x01, 0x02, 0x03, 0x04};
  for (int i = 0; i < 2000; ++i) {
    bytes.insert(bytes.end(), candidate, candidate + 12);  // claims 64 KiB that are good records
    bytes.insert(bytes.end(), record.begin(), record.end());
  }
  const Recording rec = parse_recording(bytes.data(), bytes.size());
  EXPECT_EQ(rec.frames.size(), 2000u);
  EXPECT_EQ(rec.recovery.damaged_regions, 2000u);
  EXPECT_LE(rec.recovery.checksum_bytes, bytes.size());
}
