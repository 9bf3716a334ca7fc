// softdeca convert: Live Link Face CSV takes to recordings and back.
#include <cstdio>
#include <string>

#include "command.h"
#include "options.h"
#include "read_limits_arg.h"
#include "recording/conversions.h"

namespace softdeca::cli {
namespace {
bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}
}  // namespace

int run_convert(const Args& args) {
  Options o("convert",
            "Convert a Live Link Face CSV take (Epic's app: Timecode, BlendShapeCount, 61 value columns)\n"
            "into a recording, or a recording into such a CSV; the direction follows the extensions.\n"
            "Rows where the app lost the face are skipped and counted.");
  o.positional("INPUT", "a .csv take or a .sdrec recording")
      .positional("OUTPUT", "a .sdrec recording or a .csv take")
      .option("--fps", "RATE", "timecode frames per second (default: the recording's, else 60)");
  declare_read_limits(o);
  if (!o.parse(args)) return 0;
  const recording::ReadLimits limits = read_limits(o);
  const std::string in = o.arg(0), out = o.arg(1);
  const double fps = o.given("--fps") ? o.number("--fps") : 0;
  if (o.given("--fps") && !(fps > 0 && fps <= 1000)) throw UsageError("--fps must be in (0, 1000]");
  if (ends_with(in, ".csv") && ends_with(out, ".sdrec")) {
    const auto r = recording::csv_to_recording(in, out, fps, limits);
    std::printf("%s: %zu rows, %zu frames written, %zu face-lost rows skipped, %zu malformed rows skipped, %zu rows "
                "with weights clamped to [0, 1]\n",
                out.c_str(), r.rows, r.frames, r.face_lost_rows, r.malformed_rows, r.clamped_rows);
    return 0;
  }
  if (ends_with(in, ".sdrec") && ends_with(out, ".csv")) {
    const auto r = recording::recording_to_csv(in, out, fps, limits);
    std::printf("%s: %zu frames written\n", out.c_str(), r.frames);
    return 0;
  }
  throw UsageError("convert .csv -> .sdrec or .sdrec -> .csv");
}

}  // namespace softdeca::cli
