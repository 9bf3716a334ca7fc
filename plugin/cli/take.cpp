#include "take.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "recording/livelinkface_csv.h"
#include "recording/recording_index.h"

namespace softdeca::cli {

Take read_take(const std::string& path, std::size_t max_frames, const recording::ReadLimits& limits) {
  Take take;
  take.path = path;
  std::vector<stream::Frame> frames;
  const bool csv = path.size() >= 4 && path.compare(path.size() - 4, 4, ".csv") == 0;
  if (csv) {
    recording::CsvTake t = recording::read_livelinkface_csv(path, recording::kLiveLinkFaceTimecodeRate, limits);
    take.rows = t.rows;
    take.face_lost = t.face_lost_rows;
    take.invalid = t.malformed_rows;
    take.clamped = t.clamped_rows;
    frames = std::move(t.frames);
  }
  // A recording's frames are decoded one at a time from its index (recording_index.h).
  std::unique_ptr<recording::RecordingIndex> index;
  if (!csv) {
    index = std::make_unique<recording::RecordingIndex>(recording::RecordingIndex::open(path, limits));
    const recording::Recovery& r = index->meta().recovery;
    take.rows = index->frame_count() + r.invalid_frames;
    take.invalid = r.invalid_frames;
    take.clamped = r.clamped_frames;
  }
  std::vector<double> times;
  const std::size_t count = csv ? frames.size() : index->frame_count();
  for (std::size_t k = 0; k < count; ++k) {
    const stream::Frame f = csv ? frames[k] : index->frame(k);
    if (f.tracking == stream::Tracking::lost) {
      ++take.face_lost;
      continue;
    }
    std::array<float, 52> w{};
    std::copy(f.weights.begin(), f.weights.end(), w.begin());  // in [0, 1]: the frame rule
    take.weights.push_back(w);
    times.push_back(f.capture_time);
    if (max_frames && take.weights.size() >= max_frames) break;
  }
  if (take.weights.empty()) throw std::runtime_error(path + ": no usable frame");
  std::vector<double> dt;
  for (std::size_t i = 1; i < times.size(); ++i)
    if (times[i] > times[i - 1]) dt.push_back(times[i] - times[i - 1]);
  if (!dt.empty()) {
    std::nth_element(dt.begin(), dt.begin() + static_cast<long>(dt.size() / 2), dt.end());
    take.median_frame_s = dt[dt.size() / 2];
  }
  return take;
}

}  // namespace softdeca::cli
