// FBX avatars, binary and ASCII: the input as a .fbx file through read_scene_file (the
// format check, the pre-scan of the file's structure, then assimp) and assemble_avatar
// (fuzz_scene_file.h has the properties checked).
#include "fuzz_scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  softdeca::fuzz::read_scene_bytes("fbx", "fbx", data, size);
  return 0;
}
