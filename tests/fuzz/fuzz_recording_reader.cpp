// The recording reader: any bytes open with what they hold recovered, or are refused with
// softdeca::Error; never a read out of bounds; and whatever opened can be played.
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "fuzz_check.h"
#include "recording/player.h"
#include "recording/recording_reader.h"

using namespace softdeca::recording;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    Recording rec = parse_recording(data, size);
    const Recovery& r = rec.recovery;
    FUZZ_CHECK(rec.frames.size() <= r.records);
    FUZZ_CHECK(r.skipped_bytes + r.truncated_bytes <= size);
    FUZZ_CHECK(r.checksum_bytes <= size);  // linear: no byte checksummed twice
    if (!rec.frames.empty()) {
      Player p(std::move(rec));
      p.set_loop(true);
      p.advance(0.5);
      const auto f = p.frame_at(p.position());
      FUZZ_CHECK(f.landmark_count <= softdeca::stream::kMaxLandmarks);
    }
  } catch (const softdeca::Error&) {
  }
  return 0;
}
