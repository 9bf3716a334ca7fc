// Live Link Face's CSV timecode "HH:MM:SS:FF.mmm": hours, minutes, seconds, the frame within
// the second at the timecode rate, and the thousandths of a frame (the subframe).
#pragma once

#include <string>
#include <string_view>

namespace softdeca::recording {

// Seconds since midnight; false when the text is no timecode or a field is out of range.
bool parse_timecode(std::string_view text, double rate, double& seconds);

// The timecode of `seconds` (>= 0) at an integer `rate`, subframe rounded to thousandths.
std::string format_timecode(double seconds, int rate);

}  // namespace softdeca::recording
