// softdeca info: what a recording holds and what a damaged one lost.
#include <cstdio>
#include <string>

#include "command.h"
#include "json.h"
#include "options.h"
#include "read_limits_arg.h"
#include "recording/recording_index.h"

namespace softdeca::cli {

int run_info(const Args& args) {
  Options o("info", "Describe a recording: its header, frames, duration and rate, landmark profile, and the\n"
                    "damage recovered from (skipped stretches, a cut-off last record) and the frames whose values\n"
                    "were left out or clamped (docs/recording.md, \"Values\").");
  o.positional("RECORDING", "a .sdrec file").flag("--json", "print JSON instead of text");
  declare_read_limits(o);
  if (!o.parse(args)) return 0;
  // One pass over the file; frames stay on disk (memory grows with the frame count only).
  const recording::RecordingIndex index = recording::RecordingIndex::open(o.arg(0), read_limits(o));
  const recording::RecordingMeta& rec = index.meta();
  const auto& h = rec.header;
  const std::size_t n = index.frame_count();
  const double duration = n > 1 ? index.capture_time(n - 1) - index.capture_time(0) : 0;
  const std::size_t tracked = index.tracked_frames(), with_landmarks = index.frames_with_landmarks();
  JsonObject j;
  j.text("device", h.device).text("subject", h.subject).text("source", h.source).text("clock", h.clock);
  j.number("start_unix_time", h.start_unix_time).number("timecode_rate", h.timecode_rate).text("units", h.units);
  j.number("frames", double(n)).number("tracked_frames", double(tracked));
  j.number("frames_with_landmarks", double(with_landmarks)).number("duration_s", duration);
  j.number("rate_hz", duration > 0 ? double(n - 1) / duration : 0);
  j.number("profiles", double(rec.profiles.size()));
  j.number("profile_landmarks", rec.profiles.empty() ? 0 : double(rec.profiles.back().indices.size()));
  j.number("neutral_vertices", double(rec.neutral.size() / 3));
  j.number("records", double(rec.recovery.records)).number("damaged_regions", double(rec.recovery.damaged_regions));
  j.number("skipped_bytes", double(rec.recovery.skipped_bytes));
  j.number("truncated_bytes", double(rec.recovery.truncated_bytes));
  j.number("unknown_records", double(rec.recovery.unknown_records));
  j.number("invalid_frames", double(rec.recovery.invalid_frames));
  j.number("clamped_frames", double(rec.recovery.clamped_frames));
  if (o.on("--json")) {
    std::printf("%s\n", j.str(true).c_str());
    return 0;
  }
  std::printf("%s\n  device %s, subject %s, source %s\n  %zu frames (%zu tracked, %zu with landmarks) over %.3f s",
              o.arg(0).c_str(), h.device.c_str(), h.subject.c_str(), h.source.c_str(), n, tracked, with_landmarks,
              duration);
  if (duration > 0) std::printf(", %.2f Hz", double(n - 1) / duration);
  std::printf("\n  capture clock: %s; units %s\n", h.clock.c_str(), h.units.c_str());
  if (!rec.profiles.empty())
    std::printf("  landmark profile '%s': %zu vertices (id %08x)\n", rec.profiles.back().name.c_str(),
                rec.profiles.back().indices.size(), rec.profiles.back().id);
  if (!rec.neutral.empty()) std::printf("  neutral mesh: %zu vertices\n", rec.neutral.size() / 3);
  std::printf("  %zu records; damage: %zu regions (%zu bytes) skipped, %zu bytes cut off at the end\n",
              rec.recovery.records, rec.recovery.damaged_regions, rec.recovery.skipped_bytes,
              rec.recovery.truncated_bytes);
  std::printf("  values: %zu frames left out (not finite, not a rotation), %zu with weights clamped to [0, 1]\n",
              rec.recovery.invalid_frames, rec.recovery.clamped_frames);
  return 0;
}

}  // namespace softdeca::cli
