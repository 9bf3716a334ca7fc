// Our wire format: any bytes decode or are dropped with a reason, never read out of bounds;
// what decodes re-encodes into bytes that decode to the same message.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_check.h"
#include "stream/wire_format.h"

using namespace softdeca::stream;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  wire::Message m;
  if (wire::decode(data, size, m).reason != DropReason::none) return 0;
  std::vector<uint8_t> again;
  wire::Message n;
  switch (m.envelope.type) {
    case wire::MessageType::frame:
      wire::encode_frame(m.frame, again);
      FUZZ_CHECK(wire::decode(again.data(), again.size(), n).reason == DropReason::none);
      FUZZ_CHECK(n.frame.capture_time == m.frame.capture_time && n.frame.tracking == m.frame.tracking);
      FUZZ_CHECK(n.frame.weights == m.frame.weights);
      FUZZ_CHECK(n.frame.landmark_count == m.frame.landmark_count && n.frame.landmarks == m.frame.landmarks);
      FUZZ_CHECK(n.frame.has_head == m.frame.has_head && n.frame.has_eyes == m.frame.has_eyes);
      break;
    case wire::MessageType::profile:
      wire::encode_profile(m.envelope.session_id, m.envelope.sequence, m.profile, again);
      FUZZ_CHECK(wire::decode(again.data(), again.size(), n).reason == DropReason::none);
      FUZZ_CHECK(n.profile.indices == m.profile.indices && n.profile.id == m.profile.id);
      break;
    case wire::MessageType::neutral_chunk:
      wire::encode_neutral_chunk(m.envelope.session_id, m.envelope.sequence, m.neutral, again);
      FUZZ_CHECK(wire::decode(again.data(), again.size(), n).reason == DropReason::none);
      FUZZ_CHECK(n.neutral.xyz == m.neutral.xyz);
      break;
    case wire::MessageType::request:
      wire::encode_request(m.envelope.session_id, m.envelope.sequence, m.request, again);
      FUZZ_CHECK(wire::decode(again.data(), again.size(), n).reason == DropReason::none);
      break;
  }
  return 0;
}
