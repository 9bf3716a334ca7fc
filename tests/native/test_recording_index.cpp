// Recordings read as a stream (recording_index.h): an index of a few bytes a frame, frames
// decoded on demand, and a size cap that refuses a crafted huge file at once.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "recording/player.h"
#include "recording/recording_index.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "stream_test_support.h"

using namespace softdeca;
using namespace softdeca::recording;

namespace {

std::string write_frames(const std::string& name, std::size_t n, uint16_t landmarks) {
  const std::string path = test::temp_path(name);
  RecordingWriter w(path, Header{});
  for (std::size_t i = 0; i < n; ++i) w.write(test::make_frame(static_cast<uint32_t>(i), landmarks, 7));
  return path;
}

// The attack: a valid header and two frames, then a hole to 1 TiB (a sparse file costs no disk).
TEST(RecordingIndex, AHugeSparseFileIsRefusedAtOnceNamingTheLimit) {
  const std::string path = write_frames("huge.sdrec", 2, 0);
  if (::truncate(path.c_str(), static_cast<off_t>(1) << 40) != 0) {
    std::remove(path.c_str());
    GTEST_SKIP() << "this file system does not hold a 1 TiB sparse file";
  }
  try {
    RecordingIndex::open(path);
    ADD_FAILURE() << "opened a 1 TiB recording under the default limit";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), SOFTDECA_ERROR_FORMAT);
    EXPECT_NE(std::string(e.what()).find("is 1048576 MiB, over the limit of 1024 MiB for a recording"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--max-mib"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

// Within a raised limit, a hole of zeros after the frames is walked, not read into memory:
// two frames, the rest a cut-off tail, an index of a few bytes.
TEST(RecordingIndex, AHoleWithinTheLimitIsWalkedNotHeld) {
  const std::string path = write_frames("hole.sdrec", 2, 0);
  ASSERT_EQ(::truncate(path.c_str(), static_cast<off_t>(256) << 20), 0);
  ReadLimits limits;
  limits.max_bytes = std::uint64_t{512} << 20;
  const RecordingIndex index = RecordingIndex::open(path, limits);
  EXPECT_EQ(index.frame_count(), 2u);
  EXPECT_GT(index.meta().recovery.truncated_bytes, std::size_t{255} << 20);
  EXPECT_LE(index.memory_bytes(), 64u * 2);
  std::remove(path.c_str());
}

// The index holds at most 64 bytes a frame (16 in fact), however large each frame's record is,
// and decodes the same frames the whole-file reader does.
TEST(RecordingIndex, HoldsAFewBytesAFrameAndDecodesOnDemand) {
  const std::size_t n = 3000;
  const std::string path = write_frames("index.sdrec", n, 149);
  const RecordingIndex index = RecordingIndex::open(path);
  ASSERT_EQ(index.frame_count(), n);
  EXPECT_LE(index.memory_bytes(), 64 * n);
  EXPECT_EQ(index.frames_with_landmarks(), n);
  const Recording whole = read_recording(path);
  ASSERT_EQ(whole.frames.size(), n);
  for (std::size_t i : {std::size_t{0}, n / 2, n - 1}) {
    const stream::Frame f = index.frame(i);
    EXPECT_EQ(f.capture_time, whole.frames[i].capture_time);
    EXPECT_EQ(f.weights, whole.frames[i].weights);
    EXPECT_EQ(f.landmarks, whole.frames[i].landmarks);
  }
  Player player(RecordingIndex::open(path));
  EXPECT_EQ(player.frame(n - 1).capture_time, whole.frames.back().capture_time);
  std::remove(path.c_str());
}

// A file changed under an open index: the frame is reported gone, not decoded from garbage.
TEST(RecordingIndex, AFileChangedWhileOpenIsAnError) {
  const std::string path = write_frames("changed.sdrec", 4, 0);
  const RecordingIndex index = RecordingIndex::open(path);
  ASSERT_EQ(::truncate(path.c_str(), 100), 0);
  EXPECT_THROW(index.frame(3), Error);
  std::remove(path.c_str());
}

}  // namespace
