// iFacialMocap's text packet: any bytes decode or are dropped with a reason; a decoded frame
// re-encodes into text that decodes with every weight named and within rounding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "stream/ifacialmocap_packet.h"

using namespace softdeca::stream;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Frame f;
  ifacialmocap::Presence present;
  if (ifacialmocap::decode_packet(data, size, f, present).reason != DropReason::none) return 0;
  const std::string text = ifacialmocap::encode_packet(f);
  Frame g;
  FUZZ_CHECK(ifacialmocap::decode_packet(reinterpret_cast<const uint8_t*>(text.data()), text.size(), g, present).reason ==
             DropReason::none);
  for (std::size_t i = 0; i < kBlendshapeCount; ++i) {
    FUZZ_CHECK(present[i]);
    FUZZ_CHECK(std::fabs(g.weights[i] - f.weights[i]) <= 0.0051f);
  }
  return 0;
}
