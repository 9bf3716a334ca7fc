// FBX files checked before assimp parses them. assimp reads FBX recursively, expands zlib
// arrays as it meets them and keeps a token per value: a few bytes of nesting overflow its
// stack, a small zlib bomb expands to gigabytes. The bytes are scanned here first, iteratively,
// against the import's limits; only a file that passes reaches assimp.
#pragma once

#include <cstdint>
#include <string>

#include "import_limits.h"

namespace softdeca::avatar_import {

// What the scan found (for tests and reports).
struct FbxScan {
  bool binary = false;
  std::uint32_t version = 0;          // binary: the header's version
  int depth = 0;                      // deepest nesting of records (binary) or braces (ASCII)
  std::uint64_t values = 0;           // properties (binary) or tokens (ASCII): what assimp keeps
  std::uint64_t decoded_bytes = 0;    // the arrays' bytes once expanded
  std::size_t connection_depth = 0;   // the longest chain of object-to-object connections
};

// The most an FBX file may expand to and hold, from its size: twice the file plus 200 MiB of
// arrays, within limits.max_decoded_bytes; values at most 3 times the file plus 400 MiB in
// assimp's tokens (64 bytes each).
std::uint64_t fbx_decoded_budget(std::uint64_t file_bytes, const ImportLimits& limits);
std::uint64_t fbx_value_budget(std::uint64_t file_bytes);

constexpr int kMaxFbxDepth = 64;

// Throws std::runtime_error naming `path` and what is wrong: "records nested more than 64
// deep", "an array that would expand to N bytes, more than the M ...", "a record ends beyond
// the file", "models connected more than 256 deep" or "in a cycle", ...
FbxScan scan_fbx(const std::string& bytes, const std::string& path, const ImportLimits& limits);

}  // namespace softdeca::avatar_import
