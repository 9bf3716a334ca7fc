// Reads a whole recording (recording_format.h) into memory and recovers what a damaged file
// still holds: a file cut mid-write loses at most its incomplete last record; a corrupted
// record is skipped by searching for the next good one (record_scan.h). For files, the
// product's paths (player, info, play, convert, replay) use recording_index.h instead, which
// keeps frames on disk; this reader serves tests and buffers already in memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "recording/read_limits.h"
#include "recording/record_scan.h"

namespace softdeca::recording {

struct Recording : RecordingMeta {
  std::vector<stream::Frame> frames;  // in file order, each within the frame rule
};

// Parses a whole file's bytes. Throws softdeca::Error (SOFTDECA_ERROR_FORMAT) when the header
// is missing, damaged or of another major version: without it no record can be trusted.
Recording parse_recording(const uint8_t* data, std::size_t size);

// Reads a file through RecordingIndex (its errors and limits) and decodes every frame.
Recording read_recording(const std::string& path, const ReadLimits& limits = {});

}  // namespace softdeca::recording
