// A saved fit (docs/avatars.md, "The fit file"): little-endian binary, versioned, naming the
// bundle it was made for (the SHA-256 of its manifest) and the avatar mesh (fit/mesh_hash.h).
// Read back bounded: every count is checked against the bundle's sizes and the bytes left.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fit/avatar_fit.h"

namespace softdeca::fit {

constexpr std::uint32_t kFitFileVersion = 1;

// The file's bytes.
std::vector<std::uint8_t> encode_fit(const AvatarFit& fit, const std::string& bundle_sha256, std::size_t skin_vertices);

// Throws Error(FORMAT) naming the problem: not a fit file, another version, another bundle,
// sizes that do not match the bundle, a truncated file, indices out of range, non-finite values.
AvatarFit decode_fit(const std::uint8_t* data, std::size_t size, const std::string& name, const std::string& bundle_sha256,
                     std::size_t head_vertices, std::size_t skin_vertices, std::size_t skin_triangles);

}  // namespace softdeca::fit
