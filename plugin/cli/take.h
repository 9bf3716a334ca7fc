// Takes for the runtime tools: a Live Link Face CSV (read by the streaming side's reader:
// columns by name, face-lost rows skipped and counted) or a recording of the streaming format
// (frames the tracker lost are skipped too). Weights in canonical ARKit order, within the frame
// rule both readers apply (recording/frame_rule.h): rows it refuses are counted in `invalid`.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "recording/read_limits.h"

namespace softdeca::cli {

struct Take {
  std::string path;
  std::vector<std::array<float, 52>> weights;
  std::size_t rows = 0, face_lost = 0, invalid = 0;
  std::size_t clamped = 0;  // kept with weights clamped to [0, 1] (recording/frame_rule.h)
  double median_frame_s = 0;  // median time between kept frames
};

// `.csv`: Live Link Face; anything else: a recording. At most `max_frames` frames (0: all); a
// file over `limits` is refused before it is read. Throws std::runtime_error or softdeca::Error
// naming the problem.
Take read_take(const std::string& path, std::size_t max_frames = 0, const recording::ReadLimits& limits = {});

}  // namespace softdeca::cli
