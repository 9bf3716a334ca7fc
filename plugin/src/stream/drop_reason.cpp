#include "stream/drop_reason.h"

namespace softdeca::stream {

const char* drop_reason_name(DropReason reason) {
  switch (reason) {
    case DropReason::none: return "none";
    case DropReason::undersized: return "undersized";
    case DropReason::oversized: return "oversized";
    case DropReason::bad_magic: return "bad magic";
    case DropReason::incompatible_version: return "incompatible version";
    case DropReason::bad_length: return "bad length";
    case DropReason::bad_value: return "bad value";
    case DropReason::unknown_type: return "unknown message type";
  }
  return "unknown";
}

}  // namespace softdeca::stream
