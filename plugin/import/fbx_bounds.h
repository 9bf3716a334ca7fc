// An FBX file's structure checked before assimp parses it (scene_assimp.cpp): assimp's FBX
// reader recurses once per nesting level, trusts the sizes the file declares (an array's
// element count, its compressed length, a node's end) and drops a mesh whose arrays do not add
// up without saying why. This walk reads every record once, iteratively, with 64-bit sizes:
//
// binary FBX ("Kaydara FBX Binary  \0", version; node records of 32-bit fields before version
//   7500, 64-bit from it): every node's end lies inside its parent and after its start, its
//   name and properties within it, its children end with the empty record; nesting at most
//   ImportLimits::max_fbx_depth; every property of a known type and inside the node; an array
//   (f, d, l, i, b/c) raw (its length times its element size is the bytes it holds) or zlib
//   (decompressing to exactly that length); each array and all of them together within
//   ImportLimits::max_decoded_bytes; a mesh's vertices in threes and its polygon indices within
//   them, a blend shape's indices as many as its vertices;
// ASCII FBX: braces outside strings and comments nested at most max_fbx_depth; an array's
//   declared count (*N) no more than the file can hold;
// both: the values the reader makes a token of, at about kFbxBytesPerValue each, within
//   max_decoded_bytes; the Model objects and their object-object connections, which assimp
//   turns into scene nodes by recursion once per path from the root, at most
//   ImportLimits::max_node_depth deep, max_nodes nodes in all, without a loop.
//
// Any violation throws std::runtime_error naming the file and what is wrong ("nested more than
// 64 deep", "an array that would expand to 1.5 GiB, more than the 1 GiB an avatar may decode").
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "import_limits.h"

namespace softdeca::avatar_import {

// What assimp 5.2 holds per value of an FBX file while reading it (a token and its separator),
// measured: about 140 bytes for a million one-byte properties or one-digit numbers.
constexpr std::uint64_t kFbxBytesPerValue = 144;

struct FbxSummary {
  bool binary = false;
  std::size_t meshes = 0;  // Geometry objects of class Mesh (binary files; 0 for ASCII)
  std::uint64_t values = 0, decoded_bytes = 0;
};

// Throws std::runtime_error naming `path` (see above).
FbxSummary check_fbx_bounds(const std::string& bytes, const std::string& path, const ImportLimits& limits);

}  // namespace softdeca::avatar_import
