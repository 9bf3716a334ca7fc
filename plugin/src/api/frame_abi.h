// The canonical frame and profile across the C ABI: checked copies between softdeca_frame and
// stream::Frame, and the "size known, buffer too small" pattern of array outputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "api/error_boundary.h"
#include "recording/recording_format.h"
#include "softdeca/softdeca.h"
#include "stream/frame.h"
#include "stream/wire_format.h"

namespace softdeca::api {

void frame_to_abi(const stream::Frame& in, softdeca_frame* out);
// Checks every field (finite, in range, unit rotations) before copying.
stream::Frame frame_from_abi(const softdeca_frame* in);

void profile_to_abi(const stream::wire::Profile* profile, uint32_t* out_id, int32_t* out_indices,
                    uint32_t capacity, uint32_t* out_count);
void neutral_to_abi(const std::vector<float>& xyz, float* out_xyz, uint32_t vertex_capacity,
                    uint32_t* out_vertex_count);

// A recording header from the ABI's (texts may be NULL).
recording::Header header_from_abi(const softdeca_recording_header* header);

}  // namespace softdeca::api
