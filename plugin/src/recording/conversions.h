// Live Link Face CSV takes to recordings and back (the CLI's `convert` and the C ABI).
#pragma once

#include <cstddef>
#include <string>

#include "recording/read_limits.h"

namespace softdeca::recording {

struct ConversionReport {
  std::size_t frames = 0;
  std::size_t rows = 0;
  std::size_t face_lost_rows = 0;
  std::size_t malformed_rows = 0;
  std::size_t clamped_rows = 0;
};

// timecode_rate <= 0: the app's default (60).
ConversionReport csv_to_recording(const std::string& csv_path, const std::string& recording_path,
                                  double timecode_rate, const ReadLimits& limits = {});
// timecode_rate <= 0: the recording's timecode rate, else 60. The rate must be an integer.
// The recording is read a frame at a time (recording_index.h).
ConversionReport recording_to_csv(const std::string& recording_path, const std::string& csv_path,
                                  double timecode_rate, const ReadLimits& limits = {});

}  // namespace softdeca::recording
