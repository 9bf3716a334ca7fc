// The recording file (.sdrec), version 1.0; docs/recording.md is its specification.
// A self-describing header, then append-only records, each framed as
//   "SDRC" magic | u32 payload length | u32 CRC-32 of (length, payload) | payload
// so that a reader can check every record and, after damage, find the next good one.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "stream/frame.h"
#include "stream/wire_format.h"

namespace softdeca::recording {

constexpr std::array<uint8_t, 8> kFileMagic = {0x89, 'S', 'D', 'R', 'E', 'C', '\r', '\n'};
constexpr uint16_t kVersionMajor = 1;  // a reader refuses other majors
constexpr uint16_t kVersionMinor = 0;  // newer minors add header tags, record types, fields
constexpr std::array<uint8_t, 4> kRecordMagic = {'S', 'D', 'R', 'C'};
constexpr std::size_t kRecordHeaderBytes = 12;
constexpr std::size_t kMaxRecordBytes = 1u << 16;
constexpr std::size_t kMaxHeaderBytes = 1u << 20;

enum class RecordType : uint8_t { frame = 1, profile = 2, neutral = 3 };

enum class HeaderTag : uint16_t {
  device = 1,           // text: the capturing device or app
  subject = 2,          // text: performer or take name
  source = 3,           // text: where the frames came from ("softdeca-udp", "livelinkface-csv", ...)
  start_unix_time = 4,  // f64: when recording started, seconds since 1970-01-01 UTC (0: unknown)
  timecode_rate = 5,    // f64: frames per second of a timecode clock, 0 if none
  clock = 6,            // text: what capture times count
  units = 7,            // text: "m"
  coordinate_frame = 8, // text: the frame of poses and landmarks
  blendshape_names = 9, // text: the weights' names, comma-separated, in record order
  profile = 10,         // landmark profile, as a profile record's body
  neutral = 11,         // neutral mesh, as a neutral record's body
};

struct Header {
  std::string device;
  std::string subject;
  std::string source;
  double start_unix_time = 0;
  double timecode_rate = 0;
  std::string clock = "sender seconds";
  std::string units = "m";
  std::string coordinate_frame = "ARKit face anchor: right-handed, +Y up, +Z out of the face";
  bool has_profile = false;
  stream::wire::Profile profile;
  std::vector<float> neutral;  // xyz per vertex; empty when none
};

}  // namespace softdeca::recording
