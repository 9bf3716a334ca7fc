#include "stream/datagram_decoder.h"

#include <cctype>
#include <cstring>

#include "stream/livelinkface_packet.h"

namespace softdeca::stream {
namespace {

Format recognise(const uint8_t* data, std::size_t size) {
  if (size >= wire::kMagic.size() && std::memcmp(data, wire::kMagic.data(), wire::kMagic.size()) == 0)
    return Format::softdeca;
  if (size >= 1 && data[0] == livelinkface::kPacketVersion) return Format::livelinkface;
  if (size >= 1 && std::isalpha(data[0])) return Format::ifacialmocap;
  return Format::automatic;  // none
}

}  // namespace

const char* format_name(Format format) {
  switch (format) {
    case Format::automatic: return "auto";
    case Format::softdeca: return "softdeca";
    case Format::livelinkface: return "livelinkface";
    case Format::ifacialmocap: return "ifacialmocap";
  }
  return "unknown";
}

uint16_t default_port(Format format) {
  switch (format) {
    case Format::livelinkface: return 11111;
    case Format::ifacialmocap: return 49983;
    default: return 50110;
  }
}

wire::Verdict decode_datagram(const uint8_t* data, std::size_t size, Format accepted, Datagram& out) {
  const Format format = accepted == Format::automatic ? recognise(data, size) : accepted;
  out.format = format;
  out.present.fill(true);
  switch (format) {
    case Format::softdeca:
      return wire::decode(data, size, out.message);
    case Format::livelinkface: {
      livelinkface::PacketInfo info;
      out.message.envelope = wire::Envelope{};
      return livelinkface::decode_packet(data, size, out.message.frame, info);
    }
    case Format::ifacialmocap:
      out.message.envelope = wire::Envelope{};
      return ifacialmocap::decode_packet(data, size, out.message.frame, out.present);
    case Format::automatic:
      break;
  }
  if (size == 0) return {DropReason::undersized, "empty datagram"};
  return {DropReason::bad_magic, "no format this receiver accepts"};
}

}  // namespace softdeca::stream
