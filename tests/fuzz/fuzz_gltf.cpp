// glTF 2.0 avatars: the input as a .glb file when it starts with the binary container's magic,
// else as a .gltf (JSON), through read_scene_file and assemble_avatar (fuzz_scene_file.h has
// the properties checked). A buffer named by URI is looked for beside the file, where there is
// none; names that lead out of the folder are tests/python/test_hostile_avatars.py's.
#include <cstring>

#include "fuzz_scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  softdeca::fuzz::read_scene_bytes("gltf", binary ? "glb" : "gltf", data, size);
  return 0;
}
