// One entry point for every datagram format the receiver accepts: ours, Live Link Face and
// iFacialMocap, either one chosen or recognised per datagram.
#pragma once

#include <cstddef>
#include <cstdint>

#include "stream/ifacialmocap_packet.h"
#include "stream/wire_format.h"

namespace softdeca::stream {

enum class Format : uint8_t { automatic = 0, softdeca = 1, livelinkface = 2, ifacialmocap = 3 };

const char* format_name(Format format);
// The port each format's sender uses by default (ours: 50110).
uint16_t default_port(Format format);

struct Datagram {
  Format format = Format::softdeca;  // the format that decoded it
  wire::Message message;             // third-party formats decode into message.frame
  ifacialmocap::Presence present;    // weights the datagram carried (all but for iFacialMocap)
};

// Decodes with `accepted`'s parser; `automatic` tells the formats apart by their first bytes
// (our magic, Live Link Face's version byte 6, iFacialMocap's text).
wire::Verdict decode_datagram(const uint8_t* data, std::size_t size, Format accepted, Datagram& out);

}  // namespace softdeca::stream
