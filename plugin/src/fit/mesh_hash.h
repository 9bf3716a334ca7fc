// The identity of an avatar mesh a fit belongs to: SHA-256 over its neutral positions and its
// triangles (the shapes may change without refitting; a changed mesh may not).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace softdeca::fit {

std::string mesh_sha256(const float* neutral, std::size_t vertex_count, const std::int32_t* triangles,
                        std::size_t triangle_count);

}  // namespace softdeca::fit
