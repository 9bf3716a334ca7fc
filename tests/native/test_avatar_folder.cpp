// Avatar folders (neutral.obj, blendshapes/<rig name>.obj) and mapping files of rig names
// (plugin/import/avatar_file.h, shape_names.h).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>

#include <string>
#include <vector>

#include "avatar_file.h"
#include "avatar_test_files.h"
#include "input_files.h"
#include "shape_names.h"
#include "softdeca/softdeca.h"

using namespace softdeca::avatar_import;
using softdeca::test::TempDir;
constexpr auto shape = softdeca::test::arkit_index;

namespace {
// An OBJ of a quad (two triangles) with its vertices moved by `dy` times their number.
std::string quad(float dy, std::size_t vertices = 4) {
  std::string obj;
  const float xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (std::size_t i = 0; i < vertices; ++i)
    obj += "v " + std::to_string(xy[i % 4][0]) + " " + std::to_string(xy[i % 4][1] + dy * static_cast<float>(i)) + " 0\n";
  return obj + (vertices >= 4 ? "f 1 2 3 4\n" : "f 1 2 3\n");
}

std::string error_of(const std::string& path, const ShapeNames& names = {}) {
  try {
    read_avatar_file(path, names);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(AvatarFolder, ReadsTheShapesItsNamesGiveAndListsTheRest) {
  const TempDir dir("avatar-folder");
  dir.write("head/neutral.obj", quad(0));
  dir.write("head/blendshapes/eyeBlink_L.obj", quad(0.1f));
  dir.write("head/blendshapes/EyeBlinkLeft.obj", quad(0.2f));   // the same shape again: sorted first, it wins
  dir.write("head/blendshapes/jaw_open.obj", quad(-0.3f));
  dir.write("head/blendshapes/notes.obj", quad(0, 3));         // no ARKit name: never read, so its size does not matter
  dir.write("head/blendshapes/readme.txt", "not a shape");
  const AvatarFile a = read_avatar_file(dir.file("head"));
  EXPECT_EQ(a.format, "avatar folder");
  ASSERT_EQ(a.parts.size(), 1u);
  EXPECT_EQ(a.parts[0].name, "head");
  EXPECT_EQ(a.vertex_count(), 4u);
  EXPECT_EQ(a.triangles, (std::vector<std::int32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(a.shape_count(), 2u);
  EXPECT_EQ(a.shape_sources[shape("eyeBlinkLeft")][0].rig_name, "EyeBlinkLeft");
  EXPECT_EQ(a.shape_sources[shape("jawOpen")][0].rig_name, "jaw_open");
  const std::size_t n = 4, blink = shape("eyeBlinkLeft"), jaw = shape("jawOpen");
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(a.blendshapes[3 * (blink * n + i) + 1], 0.2f * static_cast<float>(i), 1e-5);
    EXPECT_NEAR(a.blendshapes[3 * (jaw * n + i) + 1], -0.3f * static_cast<float>(i), 1e-5);
  }
  ASSERT_EQ(a.names_not_used.size(), 2u);
  EXPECT_EQ(a.names_not_used[0].name, "eyeBlink_L");
  EXPECT_EQ(a.names_not_used[0].reason, "'EyeBlinkLeft' already gives eyeBlinkLeft");
  EXPECT_EQ(a.names_not_used[1].name, "notes");
  EXPECT_EQ(a.declared_metres_per_unit, 0.0);
}

TEST(AvatarFolder, BadFoldersGetErrorsNamingTheFile) {
  const TempDir dir("avatar-folder-bad");
  dir.write("short/neutral.obj", quad(0));
  const std::string short_shape = dir.write("short/blendshapes/jawOpen.obj", quad(0.1f, 3));
  const std::string short_error = error_of(dir.file("short"));
  EXPECT_NE(short_error.find(short_shape + ": shape 'jawOpen' has 3 vertices, neutral.obj 4"), std::string::npos) << short_error;

  dir.write("nan/neutral.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  dir.write("nan/blendshapes/jawOpen.obj", quad(0.1f, 3));
  EXPECT_NE(error_of(dir.file("nan")).find("nan/neutral.obj:2: a vertex coordinate is not finite"), std::string::npos) << error_of(dir.file("nan"));

  dir.write("none/neutral.obj", quad(0));
  dir.write("none/blendshapes/smile.obj", quad(0.1f));
  EXPECT_NE(error_of(dir.file("none")).find("no mesh carries an ARKit blendshape"), std::string::npos);

  dir.write("empty/neutral.obj", "");
  EXPECT_NE(error_of(dir.file("empty")).find("is empty"), std::string::npos) << error_of(dir.file("empty"));
  EXPECT_NE(error_of(dir.file("missing")).find("not an avatar"), std::string::npos) << error_of(dir.file("missing"));
}

TEST(AvatarFolder, AMappingFileOverridesTheRuleForTheNamesItLists) {
  const TempDir dir("avatar-names");
  dir.write("head/neutral.obj", quad(0));
  dir.write("head/blendshapes/customBlink.obj", quad(0.1f));
  dir.write("head/blendshapes/jawOpen.obj", quad(0.2f));
  dir.write("head/blendshapes/mouthSmileLeft.obj", quad(0.3f));
  const std::string names = dir.write("names.txt", "# rig name -> ARKit name\ncustomBlink\teyeBlinkLeft\njawOpen = none\n\n");
  const AvatarFile a = read_avatar_file(dir.file("head"), ShapeNames::from_file(names));
  EXPECT_EQ(a.names_file, names);
  EXPECT_EQ(a.shape_sources[shape("eyeBlinkLeft")][0].rig_name, "customBlink");
  EXPECT_TRUE(a.shape_sources[shape("jawOpen")].empty());
  EXPECT_EQ(a.shape_sources[shape("mouthSmileLeft")][0].rig_name, "mouthSmileLeft");  // not listed: the rule

  const auto file_error = [&](const std::string& text) {
    try {
      ShapeNames::from_file(dir.write("bad.txt", text));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(file_error("a b\n").find("bad.txt:1: expected"), std::string::npos);
  EXPECT_NE(file_error("x=smile\n").find("bad.txt:1: 'smile' is not an ARKit blendshape name"), std::string::npos);
  EXPECT_NE(file_error("x=jawOpen\nx=jawOpen\n").find("bad.txt:2: 'x' is listed twice"), std::string::npos);
  EXPECT_NE(file_error("=jawOpen\n").find("a name is missing"), std::string::npos);
}

TEST(AvatarFolder, TheMeshHashNamesTheMeshAsRead) {
  const TempDir dir("avatar-hash");
  dir.write("head/neutral.obj", quad(0));
  dir.write("head/blendshapes/jawOpen.obj", quad(0.2f));
  const std::string first = avatar_mesh_sha256(read_avatar_file(dir.file("head")));
  EXPECT_EQ(first.size(), 64u);
  EXPECT_EQ(avatar_mesh_sha256(read_avatar_file(dir.file("head"))), first);
  dir.write("head/blendshapes/jawOpen.obj", quad(0.25f));
  EXPECT_NE(avatar_mesh_sha256(read_avatar_file(dir.file("head"))), first);
}

TEST(InputFiles, AnAvatarsOwnPathsStayInItsFolder) {
  using softdeca::avatar_import::confined_steps;
  EXPECT_EQ(confined_steps("a/./b/../c.bin"), (std::vector<std::string>{"a", "c.bin"}));
  const auto refusal = [](const std::string& path) {
    try {
      confined_steps(path);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refusal("../outside/buf.bin").find("leads out of the avatar's folder"), std::string::npos);
  EXPECT_NE(refusal("a/../../b").find("leads out"), std::string::npos);
  EXPECT_NE(refusal("/etc/passwd").find("absolute path"), std::string::npos);
  EXPECT_NE(refusal("file:buf.bin").find("drive or a scheme"), std::string::npos);
  EXPECT_NE(refusal("C:/x").find("drive or a scheme"), std::string::npos);
  EXPECT_NE(refusal("..\\x").find("backslash"), std::string::npos);
  EXPECT_NE(refusal("a/..").find("folder itself"), std::string::npos);
  EXPECT_NE(refusal("").find("empty path"), std::string::npos);
}

TEST(InputFiles, LinksFifosAndFoldersAreRefusedAtOnce) {
  const TempDir dir("input-files");
  dir.write("avatar/buf.bin", "abc");
  dir.write("secret.txt", "SECRET");
  std::filesystem::create_symlink(dir.file("secret.txt"), dir.file("avatar/link.bin"));
  std::filesystem::create_directory_symlink(dir.dir, dir.file("avatar/up"));
  ASSERT_EQ(::mkfifo(dir.file("avatar/pipe.bin").c_str(), 0600), 0);
  const softdeca::avatar_import::InputFolder folder(dir.file("avatar"));
  EXPECT_EQ(folder.read("buf.bin", 100, "a buffer"), "abc");
  const auto refusal = [&](const std::string& path, std::uint64_t max = 100) {
    try {
      folder.read(path, max, "a buffer");
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("read");
  };
  EXPECT_NE(refusal("link.bin").find("is a symbolic link"), std::string::npos) << refusal("link.bin");
  EXPECT_NE(refusal("up/secret.txt").find("'up' is a symbolic link"), std::string::npos) << refusal("up/secret.txt");
  EXPECT_NE(refusal("pipe.bin").find("is a FIFO"), std::string::npos) << refusal("pipe.bin");
  EXPECT_NE(refusal("missing.bin").find("does not exist"), std::string::npos);
  EXPECT_NE(refusal("buf.bin", 2).find("more than the 2"), std::string::npos);
  EXPECT_FALSE(folder.has_folder("up"));
  EXPECT_EQ(folder.list(".", 10).size(), 1u);  // buf.bin: links, FIFOs and folders are not listed
}
