#include "recording/conversions.h"

#include <cmath>

#include "core/error.h"
#include "recording/livelinkface_csv.h"
#include "recording/recording_index.h"
#include "recording/recording_writer.h"

namespace softdeca::recording {
namespace {
std::string stem(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.rfind('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}
}  // namespace

ConversionReport csv_to_recording(const std::string& csv_path, const std::string& recording_path,
                                  double rate, const ReadLimits& limits) {
  if (rate <= 0) rate = kLiveLinkFaceTimecodeRate;
  const CsvTake take = read_livelinkface_csv(csv_path, rate, limits);
  Header h;
  h.device = "Live Link Face";
  h.subject = stem(csv_path);
  h.source = "livelinkface-csv";
  h.timecode_rate = rate;
  h.clock = "timecode seconds since midnight";
  RecordingWriter writer(recording_path, h);
  for (const stream::Frame& f : take.frames) writer.write(f);
  return {writer.frames_written(), take.rows, take.face_lost_rows, take.malformed_rows, take.clamped_rows};
}

ConversionReport recording_to_csv(const std::string& recording_path, const std::string& csv_path,
                                  double rate, const ReadLimits& limits) {
  const RecordingIndex index = RecordingIndex::open(recording_path, limits);
  const Header& header = index.meta().header;
  if (rate <= 0) rate = header.timecode_rate > 0 ? header.timecode_rate : kLiveLinkFaceTimecodeRate;
  require(rate == std::floor(rate), "a CSV timecode rate must be a whole number of frames per second");
  CsvWriter out(csv_path, static_cast<int>(rate));
  for (std::size_t i = 0; i < index.frame_count(); ++i) out.write(index.frame(i));  // one frame in memory at a time
  out.finish();
  ConversionReport report;
  report.frames = out.rows();
  return report;
}

}  // namespace softdeca::recording
