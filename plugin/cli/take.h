// Takes for the runtime tools: a Live Link Face CSV (read by the streaming side's reader:
// columns by name, face-lost rows skipped and counted) or a recording of the streaming format
// (frames the tracker lost are skipped too). Weights in canonical ARKit order.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace softdeca::cli {

struct Take {
  std::string path;
  std::vector<std::array<float, 52>> weights;
  std::size_t rows = 0, face_lost = 0, invalid = 0;
  double median_frame_s = 0;  // median time between kept frames
};

// `.csv`: Live Link Face; anything else: a recording. At most `max_frames` frames (0: all).
// Throws std::runtime_error or softdeca::Error naming the problem.
Take read_take(const std::string& path, std::size_t max_frames = 0);

}  // namespace softdeca::cli
