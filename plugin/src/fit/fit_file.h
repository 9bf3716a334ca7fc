// A saved fit (docs/avatars.md, "The fit file"): little-endian binary, versioned, naming the
// bundle it was made for (the SHA-256 of its manifest) and the avatar mesh (fit/mesh_hash.h),
// with a SHA-256 of its content. Read back bounded: every count is checked against the
// bundle's sizes and the bytes left, every value against the ranges a fit lies in (fit/limits.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fit/avatar_fit.h"

namespace softdeca::fit {

// Version 2 added the checksum; version 1 files are refused ("fit the avatar again").
constexpr std::uint32_t kFitFileVersion = 2;
// The header: "SDECAFIT", the version (u32), then the SHA-256 (64 lower-case hex characters)
// of every byte after it.
constexpr std::size_t kFitHeaderBytes = 8 + 4 + 64;

// The bundle's sizes a fit is read for.
struct FitSizes {
  std::size_t head_vertices = 0, skin_vertices = 0, skin_triangles = 0;
  std::size_t identity_modes = 0;  // the template's identity modes (0: none)
};

// The file's bytes.
std::vector<std::uint8_t> encode_fit(const AvatarFit& fit, const std::string& bundle_sha256, std::size_t skin_vertices);

// What makes `fit` unlike every fit the library makes, in a user's words ("an embedding offset
// lies 2 m from the skin, beyond the fit's 10 mm"), or empty: an index outside its count, a
// size not the bundle's, a value not finite or outside its range (fit/limits.h), barycentric
// weights outside [0, 1] or not summing to 1. Checked when a fit is made and when it is loaded.
std::string fit_out_of_range(const AvatarFit& fit, const FitSizes& sizes);

// Throws Error(FORMAT) naming the problem: not a fit file, another version, a checksum that does
// not match ("<name> is damaged (its checksum does not match); fit the avatar again"), another
// bundle, sizes that do not match the bundle, a truncated file, or values out of range.
AvatarFit decode_fit(const std::uint8_t* data, std::size_t size, const std::string& name, const std::string& bundle_sha256,
                     const FitSizes& sizes);

}  // namespace softdeca::fit
