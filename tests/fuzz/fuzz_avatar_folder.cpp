// An avatar folder built from the input (import/avatar_folder.cpp through read_avatar_file):
// neutral.obj and one file in blendshapes/, which is a regular OBJ, a FIFO, or a link to an OBJ
// outside the folder. The read never hangs; it returns an avatar the C ABI takes, or refuses
// with std::runtime_error; a shape file that is not a regular file in the folder is never read.
//
// Input: [kind % 3][shape name % 6][neutral length, 2 bytes little-endian][neutral.obj][shape OBJ].
#include <sys/stat.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "avatar_file.h"
#include "fuzz_check.h"
#include "fuzz_files.h"
#include "fuzz_import_check.h"

namespace fs = std::filesystem;
using namespace softdeca::avatar_import;

namespace {
// Shape file names: ARKit's, two other rigs' spellings of ARKit shapes, a name the rule maps to
// nothing, and two that fold to one shape (the first, sorted, gives it).
const char* const kShapeNames[] = {"jawOpen", "eyeBlink_L", "AK_07_JawOpen", "hairWind", "mouthSmileLeft", "mouth_smile_l"};

fs::path workspace() {
  static const fs::path dir = softdeca::fuzz::workspace("avatar-folder");
  return dir;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 4) return 0;
  const int kind = data[0] % 3;
  const std::string shape_name = kShapeNames[data[1] % 6];
  const std::size_t neutral_length = std::min<std::size_t>(data[2] | std::size_t{data[3]} << 8, size - 4);
  const std::string neutral(reinterpret_cast<const char*>(data + 4), neutral_length);
  const std::string shape(reinterpret_cast<const char*>(data + 4 + neutral_length), size - 4 - neutral_length);

  const fs::path avatar = workspace() / "avatar", outside = workspace() / "outside.obj";
  std::error_code ec;
  fs::remove_all(avatar, ec);
  fs::create_directories(avatar / "blendshapes");
  softdeca::fuzz::write_file(avatar / "neutral.obj", neutral);
  const fs::path shape_file = avatar / "blendshapes" / (shape_name + ".obj");
  fs::remove(outside, ec);
  softdeca::fuzz::write_file(outside, shape);
  switch (kind) {
    case 0: softdeca::fuzz::write_file(shape_file, shape); break;
    case 1: ::mkfifo(shape_file.c_str(), 0600); break;
    case 2: fs::create_symlink("../../outside.obj", shape_file, ec); break;
  }

  ImportLimits limits;
  limits.max_vertices = 4096;
  limits.max_triangles = 8192;
  limits.max_file_bytes = 1 << 20;
  try {
    const AvatarFile a = read_avatar_file(avatar.string(), ShapeNames(), limits);
    softdeca::fuzz::check_avatar(a, limits);
    FUZZ_CHECK(a.parts.size() == 1 && a.format == "avatar folder");
    // Its one shape comes from the one shape file, so that must be a regular file in the folder.
    FUZZ_CHECK(kind == 0);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
