// Live Link Face's UDP packet: any bytes decode or are dropped with a reason; what decodes
// re-encodes into a packet that decodes to the same weights.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_check.h"
#include "stream/livelinkface_packet.h"

using namespace softdeca::stream;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Frame f;
  livelinkface::PacketInfo info;
  if (livelinkface::decode_packet(data, size, f, info).reason != DropReason::none) return 0;
  // The encoder takes a time of day: frame numbers of a negative or huge time are the
  // decoder's to accept and not the encoder's to produce.
  const double frames = f.capture_time * info.fps_numerator / info.fps_denominator;
  if (!(f.capture_time >= 0) || !(frames < 2e9)) return 0;
  std::vector<uint8_t> again;
  livelinkface::encode_packet(f, info, again);
  Frame g;
  livelinkface::PacketInfo back;
  FUZZ_CHECK(livelinkface::decode_packet(again.data(), again.size(), g, back).reason == DropReason::none);
  FUZZ_CHECK(g.weights == f.weights && g.tracking == f.tracking);
  FUZZ_CHECK(back.device_id == info.device_id && back.subject == info.subject);
  return 0;
}
