// Hostile avatar files refused with errors a user can act on, before anything of their claimed
// size exists (plugin/import/fbx_bounds.h, fit/value_bounds.h, docs/security.md "Avatar
// files"): FBX nested far deeper than any scene, zlib arrays that expand to gigabytes, arrays
// that do not add up, damaged bytes, stray vertices and shapes that move a vertex out of any
// scene. None of them crashes the reader, and no C++ library's text reaches the user.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "avatar_file.h"
#include "avatar_test_files.h"
#include "softdeca/softdeca.h"

using namespace softdeca::avatar_import;
using softdeca::test::error_of;
using softdeca::test::TempDir;
using softdeca::test::TestMesh;
using softdeca::test::TestScene;
namespace files = softdeca::test::files_detail;

namespace {

#define REQUIRE_FBX() \
  if (!fbx_files_supported()) GTEST_SKIP() << "built without assimp"

// A head of 12 vertices (an icosahedron, 1 unit across) with two ARKit shapes.
TestMesh head() {
  TestMesh m;
  m.name = "Head";
  const float t = 0.809f, u = 0.5f;
  m.vertices = {-u, t, 0, u, t, 0, -u, -t, 0, u, -t, 0, 0, -u, t, 0, u, t, 0, -u, -t, 0, u, -t, t, 0, -u, t, 0, u, -t, 0, -u, -t, 0, u};
  m.triangles = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
                 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  std::vector<float> jaw(36, 0.0f), blink(36, 0.0f);
  for (int v = 0; v < 12; ++v) {
    jaw[3 * v + 1] = m.vertices[3 * v + 1] < 0 ? -0.1f : 0.0f;
    blink[3 * v + 1] = m.vertices[3 * v + 1] > 0 ? -0.05f : 0.0f;
  }
  m.shapes = {{"jawOpen", jaw, {}}, {"eyeBlinkLeft", blink, {}}};
  return m;
}

TestScene scene(bool zlib = false) {
  TestScene s;
  s.fbx_zlib = zlib;
  s.meshes = {head()};
  return s;
}


// What no message may hold: a C++ library's own words.
bool speaks_cpp(const std::string& message) {
  for (const char* word : {"std::", "bad_alloc", "vector::", "_M_", "basic_string", "out_of_range", "length_error"})
    if (message.find(word) != std::string::npos) return true;
  return false;
}

void expect_error(const std::string& error, const std::string& path, const std::string& part) {
  EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
  EXPECT_NE(error.find(part), std::string::npos) << error;
  EXPECT_FALSE(speaks_cpp(error)) << error;
}
}  // namespace

TEST(AvatarBounds, TheTestHeadReadsRawAndCompressed) {
  REQUIRE_FBX();
  const TempDir dir("bounds-ok");
  for (const bool zlib : {false, true}) {
    const AvatarFile a = read_avatar_file(dir.write(zlib ? "zlib.fbx" : "raw.fbx", softdeca::test::fbx_bytes(scene(zlib))));
    EXPECT_EQ(a.vertex_count(), 12u);
    EXPECT_EQ(a.shape_count(), 2u);
  }
}

TEST(AvatarBounds, FbxNestedDeepIsRefusedWithoutRecursion) {
  REQUIRE_FBX();
  const TempDir dir("bounds-nested");
  const std::string binary = dir.write("deep.fbx", softdeca::test::fbx_nested_bytes(100000));
  expect_error(error_of(binary), binary, "nested more than 64 deep");
  const std::string ascii = dir.write("deep_ascii.fbx", softdeca::test::fbx_ascii_nested(100000));
  expect_error(error_of(ascii), ascii, "nested more than 64 deep (line 5)");
  // Braces inside strings and comments are not nesting.
  std::string quoted = softdeca::test::fbx_ascii_nested(3);
  quoted += "Name: \"" + std::string(1000, '{') + "\"\n; " + std::string(1000, '{') + "\n";
  const std::string quoted_path = dir.write("quoted.fbx", quoted);
  EXPECT_EQ(error_of(quoted_path).find("nested more than"), std::string::npos) << error_of(quoted_path);
  ImportLimits shallow;
  shallow.max_fbx_depth = 2;
  const std::string ok = dir.write("head.fbx", softdeca::test::fbx_bytes(scene()));
  expect_error(error_of(ok, shallow), ok, "nested more than 2 deep");
}

TEST(AvatarBounds, ModelHierarchiesDeepOrExplodingAreRefused) {
  REQUIRE_FBX();
  const TempDir dir("bounds-models");
  const double zero[3] = {0, 0, 0}, one[3] = {1, 1, 1};
  // `count` bones under the root; `link` connects bone i (id 5000 + i) to its parents.
  const auto skeleton = [&](const std::string& name, int count, const std::function<void(files::FbxNode&, int)>& link) {
    return dir.write(name, softdeca::test::fbx_bytes(
                               scene(),
                               [&](files::FbxNode& objects) {
                                 for (int i = 0; i < count; ++i)
                                   objects.children.push_back(files::fbx_model(5000 + i, "Bone" + std::to_string(i), "LimbNode", zero, zero, one));
                               },
                               [&](files::FbxNode& connections) {
                                 for (int i = 0; i < count; ++i) link(connections, i);
                               }));
  };
  const auto oo = [](std::int64_t child, std::int64_t parent) {
    return files::FbxNode{"C", {files::fbx_string("OO"), files::fbx_long(child), files::fbx_long(parent)}, {}};
  };
  // A chain of 10,000 bones: assimp's recursion over it overflows its stack.
  const std::string chain = skeleton("chain.fbx", 10000, [&](files::FbxNode& c, int i) { c.children.push_back(oo(5000 + i, i ? 4999 + i : 0)); });
  expect_error(error_of(chain), chain, "objects connected more than 256 deep");
  // A ladder of 40 rungs, each bone a child of both bones of the rung above: 2^40 paths.
  const std::string ladder = skeleton("ladder.fbx", 80, [&](files::FbxNode& c, int i) {
    if (i < 2) {
      c.children.push_back(oo(5000 + i, 0));
    } else {
      c.children.push_back(oo(5000 + i, 5000 + 2 * (i / 2 - 1)));
      c.children.push_back(oo(5000 + i, 5001 + 2 * (i / 2 - 1)));
    }
  });
  expect_error(error_of(ladder), ladder, "its models make more than 100000 scene nodes");
  const std::string loop = skeleton("loop.fbx", 3, [&](files::FbxNode& c, int i) {
    c.children.push_back(oo(5000 + i, 5000 + (i + 1) % 3));
    if (i == 0) c.children.push_back(oo(5000, 0));
  });
  expect_error(error_of(loop), loop, "objects connected in a cycle");
  // A skeleton of 300 bones, 20 deep, reads.
  const std::string bones = skeleton("bones.fbx", 300, [&](files::FbxNode& c, int i) { c.children.push_back(oo(5000 + i, i < 15 ? 0 : 4985 + i)); });
  EXPECT_EQ(error_of(bones), "");
  // The same chain in ASCII.
  std::string text = "; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n}\nObjects:  {\n";
  for (int i = 0; i < 1000; ++i) text += "\tModel: " + std::to_string(5000 + i) + ", \"Model::B\", \"LimbNode\" {\n\t}\n";
  text += "}\nConnections:  {\n";
  for (int i = 0; i < 1000; ++i) text += "\tC: \"OO\"," + std::to_string(5000 + i) + "," + std::to_string(i ? 4999 + i : 0) + "\n";
  const std::string ascii = dir.write("chain_ascii.fbx", text + "}\n");
  expect_error(error_of(ascii), ascii, "objects connected more than 256 deep");
}

TEST(AvatarBounds, BlendShapesTheReaderWouldCopyPerCornerAreBounded) {
  REQUIRE_FBX();
  const TempDir dir("bounds-shapes");
  // 100 shapes on a mesh of a million polygon corners (4 MB of indexes, 4 KB compressed):
  // assimp would copy the corners' positions and normals for each, 2.3 GiB.
  TestScene many = scene();
  for (int k = 0; k < 98; ++k) many.meshes[0].shapes.push_back({"extra" + std::to_string(k), std::vector<float>(36, 0.0f), {}});
  const std::string path = dir.write("corners.fbx", softdeca::test::fbx_bytes(many, [](files::FbxNode& objects) {
    softdeca::test::fbx_find(objects, "PolygonVertexIndex")->properties[0] = files::fbx_array_declared('i', 1000000, 1, files::zlib_zeros(4000000));
  }));
  expect_error(error_of(path), path,
               "mesh 'Head': its 100 blend shapes over 1000000 polygon corners would take the reader 2.28 GiB (a copy of the "
               "corners for each), more than the 1 GiB an avatar may decode");
  // The same shapes on the head's own 60 corners read.
  EXPECT_EQ(error_of(dir.write("head.fbx", softdeca::test::fbx_bytes(many))), "");
}

TEST(AvatarBounds, AZlibBombIsRefusedByItsDeclaredSize) {
  REQUIRE_FBX();
  const TempDir dir("bounds-bomb");
  // 1.5 GiB of zeros in a 10 MB zlib stream, declared as the head's vertices: more than a file of
  // its size may expand to (twice its size and 200 MiB), more than any avatar may decode.
  const std::uint64_t bytes = 3ull << 29;
  const std::string bomb = files::zlib_zeros(bytes);
  ASSERT_LT(bomb.size(), 11u << 20);
  const std::string path = dir.write("bomb.fbx", softdeca::test::fbx_bytes(scene(), [&](files::FbxNode& objects) {
    softdeca::test::fbx_find(objects, "Vertices")->properties[0] =
        files::fbx_array_declared('d', static_cast<std::uint32_t>(bytes / 8), 1, bomb);
  }));
  expect_error(error_of(path), path,
               "node 'Objects/Geometry/Vertices': an array that would expand to 1.5 GiB, more than the 219 MiB a file of 9.68 MiB "
               "may expand to");
  ImportLimits tight;
  tight.max_decoded_bytes = 100 << 20;
  expect_error(error_of(path, tight), path, "an array that would expand to 1.5 GiB, more than the 100 MiB an avatar may decode");

  // Arrays each within the bound, together beyond it: the budget is the file's.
  ImportLimits small;
  small.max_decoded_bytes = 1 << 20;
  const std::string many = dir.write("many.fbx", softdeca::test::fbx_bytes(scene(), [&](files::FbxNode& objects) {
    files::FbxNode& geometry = objects.children[1];
    for (int k = 0; k < 3; ++k)
      geometry.children.push_back({"Blob", {files::fbx_array_declared('d', 48 << 10, 1, files::zlib_zeros(384 << 10))}, {}});
  }));
  expect_error(error_of(many, small), many, "its arrays would expand to more than the 1 MiB an avatar may decode");
  EXPECT_EQ(error_of(many), "") << "within the default bound the same file reads";

  // A stream that expands beyond what its array declares, or is cut short.
  const auto vertices_as = [&](const std::string& name, const std::string& data) {
    return dir.write(name, softdeca::test::fbx_bytes(scene(), [&](files::FbxNode& objects) {
      softdeca::test::fbx_find(objects, "Vertices")->properties[0] = files::fbx_array_declared('d', 36, 1, data);
    }));
  };
  const std::string longer = vertices_as("longer.fbx", files::zlib_zeros(36 * 8 + 1));
  expect_error(error_of(longer), longer, "an array whose compressed data is damaged or not the 288 bytes it declares");
  const std::string stream = files::zlib_zeros(36 * 8);
  const std::string cut = vertices_as("cut.fbx", stream.substr(0, stream.size() / 2));
  expect_error(error_of(cut), cut, "damaged");
}

TEST(AvatarBounds, ArraysThatDoNotAddUpAreNamed) {
  REQUIRE_FBX();
  const TempDir dir("bounds-arrays");
  const auto edited = [&](const std::string& name, const std::function<void(files::FbxNode&)>& edit) {
    return dir.write(name, softdeca::test::fbx_bytes(scene(), edit));
  };
  // A raw array whose byte count is not its element count times the element's size; one whose
  // product wraps in 32 bits (2^29 + 1 doubles "in" 8 bytes) is seen at its full size.
  const std::string short_raw = edited("short.fbx", [](files::FbxNode& objects) {
    softdeca::test::fbx_find(objects, "Vertices")->properties[0] = files::fbx_array_declared('d', 36, 0, std::string(8, '\0'));
  });
  expect_error(error_of(short_raw), short_raw, "node 'Objects/Geometry/Vertices': an array of 36 elements that holds 8 bytes");
  const std::string wrapped = edited("wrapped.fbx", [](files::FbxNode& objects) {
    softdeca::test::fbx_find(objects, "Vertices")->properties[0] = files::fbx_array_declared('d', (1u << 29) + 1, 0, std::string(8, '\0'));
  });
  expect_error(error_of(wrapped), wrapped, "an array that would expand to 4 GiB");
  const std::string seventeen = edited("seventeen.fbx", [](files::FbxNode& objects) {
    softdeca::test::fbx_find(objects, "Vertices")->properties[0] = files::fbx_array('d', std::vector<double>(17, 0.5));
  });
  expect_error(error_of(seventeen), seventeen, "a mesh's Vertices hold 17 numbers, not a multiple of 3");
  const std::string beyond = edited("beyond.fbx", [](files::FbxNode& objects) {
    std::vector<std::int32_t> polygons = {0, 1, ~12};
    softdeca::test::fbx_find(objects, "PolygonVertexIndex")->properties[0] = files::fbx_array('i', polygons, true);
  });
  expect_error(error_of(beyond), beyond, "node 'Objects/Geometry': a polygon names vertex 12 of a mesh of 12");
  const std::string shape = edited("shape.fbx", [](files::FbxNode& objects) {
    for (files::FbxNode& o : objects.children)
      if (o.name == "Geometry" && o.properties.size() == 3 && o.properties[2].bytes.find("Shape") != std::string::npos) {
        o.children[1].properties[0] = files::fbx_array('i', std::vector<std::int32_t>{0, 1});
        break;
      }
  });
  expect_error(error_of(shape), shape, "a blend shape of 2 indexes and");
  const std::string unknown = edited("unknown.fbx", [](files::FbxNode& objects) {
    objects.children.push_back({"Odd", {{'Q', std::string(4, '\0')}}, {}});
  });
  expect_error(error_of(unknown), unknown, "node 'Objects/Odd': a property of unknown type");
  // A mesh assimp leaves out for what the walk does not check (here, no polygons) is named.
  const std::string empty = edited("empty.fbx", [](files::FbxNode& objects) {
    softdeca::test::fbx_find(objects, "PolygonVertexIndex")->properties[0] = files::fbx_array('i', std::vector<std::int32_t>{});
  });
  const std::string empty_error = error_of(empty);
  EXPECT_FALSE(speaks_cpp(empty_error)) << empty_error;
  EXPECT_NE(empty_error.find("none of its 1 meshes could be read"), std::string::npos) << empty_error;
}

TEST(AvatarBounds, AsciiFbxValuesAndDeclaredCountsAreBounded) {
  REQUIRE_FBX();
  const TempDir dir("bounds-ascii");
  const std::string header = "; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n}\n";
  const std::string huge = dir.write("huge_count.fbx", header + "Objects: {\n\tGeometry: 1, \"Geometry::\", \"Mesh\" {\n"
                                                                "\t\tVertices: *4000000000 {\n\t\t\ta: 0,0,0\n\t\t}\n\t}\n}\n");
  expect_error(error_of(huge), huge, "line 7: an array that declares 4000000000 values, more than the rest of the file can hold");
  ImportLimits small;
  small.max_decoded_bytes = 1 << 20;  // about 7,000 values
  std::string numbers = header + "Objects: {\n\tBlob: *10000 {\n\t\ta: ";
  for (int i = 0; i < 10000; ++i) numbers += "1,";
  const std::string many = dir.write("many.fbx", numbers + "1\n\t}\n}\n");
  expect_error(error_of(many, small), many, "an ASCII FBX of more than");
}

TEST(AvatarBounds, DamagedBytesNeverCrashNorSpeakCpp) {
  REQUIRE_FBX();
  const TempDir dir("bounds-flips");
  std::mt19937 random(11);
  for (const bool zlib : {false, true}) {
    const std::string good = softdeca::test::fbx_bytes(scene(zlib));
    std::uniform_int_distribution<std::size_t> at(27, good.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255);
    for (int i = 0; i < 150; ++i) {
      std::string bytes = good;
      for (int k = 0; k < 1 + i % 4; ++k) bytes[at(random)] = static_cast<char>(byte(random));
      const std::string path = dir.write("flip.fbx", bytes);
      const std::string error = error_of(path);
      if (error.empty()) continue;  // the flip hit a value that reads as another
      EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
      EXPECT_FALSE(speaks_cpp(error)) << error;
    }
    for (std::size_t cut = 27; cut < good.size(); cut += 97) {
      const std::string path = dir.write("cut.fbx", good.substr(0, cut));
      EXPECT_FALSE(speaks_cpp(error_of(path))) << error_of(path);
    }
  }
}

TEST(AvatarBounds, StrayVerticesAndHugeShapeDeltasAreRefusedByName) {
  const TempDir dir("bounds-values");
  TestScene far = scene();
  far.meshes[0].vertices[3 * 7] = 1e30f;
  const std::string far_path = dir.write("far.glb", softdeca::test::glb_bytes(far));
  expect_error(error_of(far_path), far_path, "mesh 'Head': vertex 7 lies at (1e+30, 0.5, -0.809), far outside the mesh");
  TestScene wild = scene();
  wild.meshes[0].shapes[0].deltas[3 * 4 + 2] = 3e38f;
  const std::string wild_path = dir.write("wild.glb", softdeca::test::glb_bytes(wild));
  expect_error(error_of(wild_path), wild_path, "mesh 'Head': shape 'jawOpen' moves vertex 4 by 3e+38, more than 2 times the avatar's size");
  // Within the bound (a jaw opening as far as the head is tall) reads.
  TestScene open = scene();
  open.meshes[0].shapes[0].deltas[3 * 4 + 1] = -1.5f;
  EXPECT_EQ(error_of(dir.write("open.glb", softdeca::test::glb_bytes(open))), "");
}
