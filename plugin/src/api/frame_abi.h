// The canonical frame and profile across the C ABI: checked copies between softdeca_frame and
// stream::Frame, and the "size known, buffer too small" pattern of array outputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "api/error.h"
#include "recording/recording_format.h"
#include "softdeca/softdeca.h"
#include "stream/frame.h"
#include "stream/wire_format.h"

namespace softdeca::abi {

// Rejects a null struct or a `size` smaller than this library's struct.
template <class T>
void require_struct(const T* s, const char* name) {
  require_not_null(s, name);
  require(s->size >= sizeof(T), std::string(name) + "->size is smaller than sizeof(" + name +
                                    "): set it to sizeof the struct");
}

void frame_to_abi(const stream::Frame& in, softdeca_frame* out);
// Checks every field (finite, in range, unit rotations) before copying.
stream::Frame frame_from_abi(const softdeca_frame* in);

void profile_to_abi(const stream::wire::Profile* profile, uint32_t* out_id, uint16_t* out_indices,
                    std::size_t capacity, std::size_t* out_count);
void neutral_to_abi(const std::vector<float>& xyz, float* out_xyz, std::size_t vertex_capacity,
                    std::size_t* out_vertex_count);

// A recording header from the ABI's (texts may be NULL).
recording::Header header_from_abi(const softdeca_recording_header* header);

}  // namespace softdeca::abi
