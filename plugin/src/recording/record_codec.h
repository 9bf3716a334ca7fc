// Bodies of the header and of the records (recording_format.h): encoders used by the writer,
// decoders used by the reader. Decoders take untrusted bytes and return false on anything
// malformed, never reading outside the span they are given.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "recording/recording_format.h"
#include "stream/byte_io.h"

namespace softdeca::recording {

void encode_header_fields(const Header& header, std::vector<uint8_t>& out);
// Fills header; `weight_order` receives, per stored weight, its canonical index (-1: unknown
// name, dropped). False on malformed fields; unknown tags are skipped.
bool decode_header_fields(stream::ByteReader& r, Header& header, std::vector<int>& weight_order);

void encode_frame_record(const stream::Frame& frame, std::vector<uint8_t>& out);
void encode_profile_record(const stream::wire::Profile& profile, std::vector<uint8_t>& out);
void encode_neutral_record(const std::vector<float>& xyz, std::vector<uint8_t>& out);

// Record bodies after the type byte (a profile body is stream::wire::read_profile_body's).
// A frame's values come as written: false only when the record's layout is broken.
bool decode_frame_record(stream::ByteReader& r, const std::vector<int>& weight_order,
                         stream::Frame& frame);
bool decode_neutral_body(stream::ByteReader& r, std::vector<float>& xyz);

}  // namespace softdeca::recording
