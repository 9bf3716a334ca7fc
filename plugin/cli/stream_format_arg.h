// The --format argument of the streaming commands.
#pragma once

#include <string>

#include "options.h"
#include "stream/datagram_decoder.h"

namespace softdeca::cli {

inline stream::Format parse_format(const std::string& text, bool allow_auto) {
  for (auto f : {stream::Format::automatic, stream::Format::softdeca, stream::Format::livelinkface,
                 stream::Format::ifacialmocap})
    if (text == stream::format_name(f) && (allow_auto || f != stream::Format::automatic)) return f;
  throw UsageError("unknown --format '" + text + "'");
}

}  // namespace softdeca::cli
