// Live Link Face's CSV takes: "Timecode,BlendShapeCount,<61 value columns>", one row per frame.
// Columns are found by name (the app's CSV orders JawLeft/JawRight and MouthLeft/MouthRight
// unlike its UDP packet, and newer versions spell BlendshapeCount). Rows where the app lost the
// face carry only the timecode and a zero count: they are skipped and counted.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "core/regular_file.h"
#include "recording/read_limits.h"
#include "stream/frame.h"

namespace softdeca::recording {

constexpr double kLiveLinkFaceTimecodeRate = 60;  // the app's default timecode clock

struct CsvTake {
  std::vector<stream::Frame> frames;  // capture_time: timecode seconds since midnight
  std::size_t rows = 0;
  std::size_t face_lost_rows = 0;  // skipped: the app had no face
  std::size_t malformed_rows = 0;  // skipped: wrong field count, bad number or timecode, or
                                   // values the frame rule refuses (frame_rule.h)
  std::size_t clamped_rows = 0;    // kept with weights clamped to [0, 1] (the frame rule)
};

// Throws softdeca::Error (FORMAT) when the header lacks Timecode or a blendshape column.
CsvTake parse_livelinkface_csv(std::string_view text, double timecode_rate);
CsvTake read_livelinkface_csv(const std::string& path, double timecode_rate, const ReadLimits& limits = {});

// The CSV of frames (tracked ones; others have nothing to write) in the app's column order;
// each value the shortest text that reads back as the same float.
std::string format_livelinkface_csv(const std::vector<stream::Frame>& frames, int timecode_rate);
std::string csv_header(int timecode_rate);
// Appends the frame's row; false (nothing appended) for a frame that is not tracked.
bool append_csv_row(std::string& out, const stream::Frame& frame, int timecode_rate);

// Writes a CSV take row by row, so that a recording's frames need not all be in memory.
class CsvWriter {
 public:
  CsvWriter(const std::string& path, int timecode_rate);  // a regular file (core/regular_file.h)
  void write(const stream::Frame& frame);
  void finish();  // throws softdeca::Error (IO) when the file could not be written
  std::size_t rows() const { return rows_; }

 private:
  void flush();
  static constexpr std::size_t kFlushBytes = std::size_t{1} << 16;
  std::string path_;
  int rate_;
  std::string text_;
  FilePtr file_;
  std::size_t rows_ = 0;
};
void write_livelinkface_csv(const std::string& path, const std::vector<stream::Frame>& frames,
                            int timecode_rate);

}  // namespace softdeca::recording
