// Live Link Face's CSV takes: "Timecode,BlendShapeCount,<61 value columns>", one row per frame.
// Columns are found by name (the app's CSV orders JawLeft/JawRight and MouthLeft/MouthRight
// unlike its UDP packet, and newer versions spell BlendshapeCount). Rows where the app lost the
// face carry only the timecode and a zero count: they are skipped and counted.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

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
CsvTake read_livelinkface_csv(const std::string& path, double timecode_rate);

// The CSV of frames (tracked ones; others have nothing to write) in the app's column order.
std::string format_livelinkface_csv(const std::vector<stream::Frame>& frames, int timecode_rate);
void write_livelinkface_csv(const std::string& path, const std::vector<stream::Frame>& frames,
                            int timecode_rate);

}  // namespace softdeca::recording
