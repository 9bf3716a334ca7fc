// Reads a recording (recording_format.h) and recovers what a damaged file still holds:
// a file cut mid-write loses at most its incomplete last record; a corrupted record is skipped
// by searching for the next record whose magic, length and checksum are all good. The search
// is linear in the file: candidates' checksums come from prefix checksums, so no byte is
// checksummed more than once however many candidates overlap it (docs/security.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "recording/recording_format.h"

namespace softdeca::recording {

struct Recovery {
  std::size_t records = 0;           // good records read
  std::size_t damaged_regions = 0;   // stretches skipped to reach the next good record
  std::size_t skipped_bytes = 0;     // bytes in those stretches
  std::size_t truncated_bytes = 0;   // end of file after the last good record: a cut-off record
  std::size_t unknown_records = 0;   // good records of a type this version does not know
  std::size_t checksum_bytes = 0;    // bytes run through CRC-32: at most the file's size
  // Frames whose values break the frame rule (frame_rule.h): left out, or kept with their
  // weights clamped to [0, 1].
  std::size_t invalid_frames = 0;
  std::size_t clamped_frames = 0;
};

struct Recording {
  Header header;
  std::vector<stream::Frame> frames;                // in file order, each within the frame rule
  std::vector<stream::wire::Profile> profiles;      // the header's, then any recorded later
  std::vector<float> neutral;                       // the last neutral mesh in the file, if any
  Recovery recovery;
};

// Parses a whole file's bytes. Throws softdeca::Error (SOFTDECA_ERROR_FORMAT) when the header
// is missing, damaged or of another major version: without it no record can be trusted.
Recording parse_recording(const uint8_t* data, std::size_t size);

// Reads and parses a file; SOFTDECA_ERROR_IO when it cannot be read.
Recording read_recording(const std::string& path);

}  // namespace softdeca::recording
