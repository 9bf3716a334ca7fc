// The two ways a glTF 2.0 file holds its JSON: as the whole of a .gltf, or as the first chunk of
// the binary container (.glb, .vrm: a 12-byte header, a JSON chunk, an optional BIN chunk, and
// chunks of other types that are skipped). Every length the container states is checked against
// the file's size in 64 bits before anything of that length is read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace softdeca::avatar_import::gltf {

struct Container {
  std::string json;  // the JSON text (a UTF-8 byte order mark and a binary chunk's padding dropped)
  bool binary = false;
  // The BIN chunk: where its bytes lie in the file, when the file has one.
  std::optional<std::size_t> bin_offset;
  std::size_t bin_length = 0;
};

// `bytes` is the whole file. Throws Problem (no place: the container as a whole) when the header
// or a chunk is malformed, or the JSON is longer than `max_json_bytes`.
Container split_container(const std::string& bytes, bool binary, std::uint64_t max_json_bytes);

}  // namespace softdeca::avatar_import::gltf
