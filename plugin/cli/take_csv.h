// Live Link Face CSV takes for the runtime tools: columns by name (the CSV's order differs from
// the UDP packet's; `BlendShapeCount` and `BlendshapeCount` both occur), face-lost rows (too few
// fields) skipped and counted, weights in canonical ARKit order.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace softdeca::cli {

struct Take {
  std::string path;
  std::vector<std::array<float, 52>> weights;
  std::vector<double> seconds;  // from the timecode (60 fps timecode clock)
  std::size_t rows = 0, face_lost = 0, invalid = 0;
  double median_frame_s = 0;  // median time between kept rows
};

// Reads at most `max_frames` frames (0: all). Throws std::runtime_error naming the problem.
Take read_livelinkface_csv(const std::string& path, std::size_t max_frames = 0);

}  // namespace softdeca::cli
