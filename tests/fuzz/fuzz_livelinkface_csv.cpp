// Live Link Face CSV takes: any text parses or is refused with softdeca::Error; the counts add up.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.h"
#include "fuzz_check.h"
#include "recording/livelinkface_csv.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto take =
        softdeca::recording::parse_livelinkface_csv(std::string_view(reinterpret_cast<const char*>(data), size), 60);
    FUZZ_CHECK(take.frames.size() + take.face_lost_rows + take.malformed_rows == take.rows);
  } catch (const softdeca::Error&) {
  }
  return 0;
}
