// What a Draco stream declares before any of it is decoded: its method and the counts its
// decoder sizes its tables by. libdraco allocates those tables as soon as it reads the counts,
// so they are checked against the glTF's own accessors (which the decode budget already bounds)
// before libdraco sees the stream. A reader of the stream's layout only: no libdraco here, so
// builds without it, and the fuzz target, read it too.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace softdeca::avatar_import::gltf {

struct DracoCounts {
  bool edgebreaker = false;     // else sequential
  std::uint64_t vertices = 0;   // sequential: its points; edgebreaker: its encoded vertices
  std::uint64_t faces = 0;
};

// The counts of a triangle-mesh Draco stream of bitstream version 2.2 (the version
// KHR_draco_mesh_compression names), past its metadata section if it has one. Throws Problem at
// `where` for another format, version or geometry type, or a stream that ends early.
DracoCounts read_draco_counts(std::string_view bytes, const std::string& where);

}  // namespace softdeca::avatar_import::gltf
