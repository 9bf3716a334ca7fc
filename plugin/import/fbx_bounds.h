// An FBX file's structure checked before assimp parses it (scene_assimp.cpp): assimp's FBX
// reader recurses once per nesting level, trusts the sizes the file declares (an array's
// element count, its compressed length, a node's end), keeps a token per value, copies a
// mesh's corners for every blend shape and drops a mesh whose arrays do not add up without
// saying why. This scan reads every record once, iteratively, with 64-bit sizes:
//
// binary FBX ("Kaydara FBX Binary  \0", version; node records of 32-bit fields before version
//   7500, 64-bit from it): every node's end lies inside its parent and after its start, its
//   name and properties within it, its children end with the empty record; nesting at most
//   ImportLimits::max_fbx_depth; every property of a known type and inside the node; an array
//   (f, d, l, i, b/c) raw (its length times its element size is the bytes it holds) or zlib
//   (decompressing to exactly that length, where the build has zlib); a mesh's vertices in
//   threes and its polygon indices within them, a blend shape's indices as many as its
//   vertices;
// ASCII FBX: braces outside strings and comments nested at most max_fbx_depth; an array's
//   declared count (*N) no more than the file can hold;
// both: each array and all of them together within fbx_decoded_budget(); the tokens the reader
//   keeps within fbx_token_budget(); the object-object connections at most
//   ImportLimits::max_node_depth deep and without a cycle, the Model objects making at most
//   max_nodes scene nodes (assimp makes one per path from the root); each mesh's polygon
//   corners copied for its blend shapes within max_decoded_bytes.
//
// Any violation throws std::runtime_error naming the file and what is wrong: the limits in
// their own words ("nested more than 64 deep", "an array that would expand to 1.5 GiB, more
// than ..."), a broken structure as "not a readable FBX file: node 'Objects/Geometry': ...".
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "import_limits.h"

namespace softdeca::avatar_import {

// What assimp 5.2 holds per token (a value, a separator, a key) while reading a file, measured:
// about 140 bytes for each of a million one-byte properties or one-digit numbers with commas.
constexpr std::uint64_t kFbxBytesPerToken = 72;

// The most a file of `file_bytes` may expand to: its arrays at most twice the file plus 200 MiB
// (a 1.5 MB zlib bomb of 1.5 GiB is refused), its tokens at most 3 times the file plus 400 MiB
// worth; each within limits.max_decoded_bytes.
std::uint64_t fbx_decoded_budget(std::uint64_t file_bytes, const ImportLimits& limits);
std::uint64_t fbx_token_budget(std::uint64_t file_bytes, const ImportLimits& limits);

// What the scan found.
struct FbxScan {
  bool binary = false;
  std::uint32_t version = 0;         // binary: the header's version
  int depth = 0;                     // deepest nesting of records (binary) or braces (ASCII)
  std::uint64_t values = 0;          // tokens the reader keeps
  std::uint64_t decoded_bytes = 0;   // the arrays' bytes once expanded
  std::size_t connection_depth = 0;  // the longest chain of object-object connections
  std::size_t meshes = 0;            // Geometry objects of class Mesh
};

// Throws std::runtime_error naming `path` (see above).
FbxScan scan_fbx(const std::string& bytes, const std::string& path, const ImportLimits& limits);

}  // namespace softdeca::avatar_import
