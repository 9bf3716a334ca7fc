// Users' avatars in glTF and FBX read into the fit's one mesh (plugin/import/avatar_file.h): which
// meshes are included, their vertex order, the ARKit shapes found under rigs' names and their
// deltas, the parts' transforms and the way back to each part's own coordinates; hostile files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "avatar_file.h"
#include "avatar_test_files.h"
#include "avatar_weld.h"
#include "fbx_bounds.h"
#include "mesh_io.h"
#include "part_space.h"
#include "softdeca/softdeca.h"

using namespace softdeca::cli;
using namespace softdeca::avatar_import;
using softdeca::test::expected_transform;
using softdeca::test::error_of;
using softdeca::test::TempDir;
constexpr auto shape = softdeca::test::arkit_index;
using softdeca::test::deltas;
using softdeca::test::TestMesh;
using softdeca::test::TestScene;
using softdeca::test::TestShape;

namespace {
// An octahedron whose vertex order differs from the order its triangles first use them.
TestMesh head() {
  TestMesh m;
  m.name = "Head";
  m.vertices = {0, 0, 1, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 0, 0, -1};
  m.triangles = {4, 1, 0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 1, 4, 5, 2, 1, 5, 3, 2, 5, 4, 3, 5};
  m.shapes = {{"blendShape1.eyeBlinkLeft", deltas(6, 0.001f), {}},
              {"AK_07_JawOpen", deltas(6, -0.002f, 3), {}},
              {"mouthSmile_L", deltas(6, 0.003f), deltas(6, 0.0015f)},
              {"eyeBlinkLeft_corrective", deltas(6, 0.004f), {}}};
  m.translation[1] = 150;
  m.rotation_y_degrees = 90;
  return m;
}

TestMesh teeth() {
  TestMesh m;
  m.name = "Teeth";
  m.vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.triangles = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
  m.shapes = {{"jawOpen", deltas(4, -0.005f), {}}};
  m.translation[1] = 145;
  m.translation[2] = 5;
  m.scale[0] = m.scale[1] = m.scale[2] = 2;
  return m;
}

TestMesh hair() {
  TestMesh m;
  m.name = "Hair";
  m.vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.triangles = {0, 1, 2};
  m.shapes = {{"hairWind", deltas(3, 0.01f), {}}};
  return m;
}

TestScene avatar_scene() {
  TestScene s;
  s.root_scale = 0.01;
  s.meshes = {head(), teeth(), hair()};
  return s;
}

std::vector<double> apply(const std::vector<double>& m, const float* p, bool point = true) {
  std::vector<double> out(3);
  for (int i = 0; i < 3; ++i) out[i] = m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + (point ? m[4 * i + 3] : 0);
  return out;
}

void expect_near3(const float* got, const std::vector<double>& want, double tolerance, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], tolerance) << what << " coordinate " << c;
}

// The part of `avatar` for mesh `mesh` of the scene, its vertex i of the file at avatar vertex
// first + order[i]: every vertex position, shape delta and the transform checked.
void expect_part(const AvatarFile& avatar, const AvatarPart& part, const TestScene& scene, const TestMesh& mesh,
                 const std::vector<std::size_t>& order) {
  const std::vector<double> m = expected_transform(scene, mesh);
  for (int k = 0; k < 16; ++k) EXPECT_NEAR(part.transform[k], m[k], 1e-6) << mesh.name << " transform " << k;
  ASSERT_EQ(part.vertex_count, mesh.vertices.size() / 3);
  const std::size_t n = avatar.vertex_count();
  for (std::size_t i = 0; i < part.vertex_count; ++i) {
    const std::size_t v = part.first_vertex + order[i];
    expect_near3(&avatar.neutral[3 * v], apply(m, &mesh.vertices[3 * i]), 1e-5, mesh.name + " vertex " + std::to_string(i));
    for (const TestShape& s : mesh.shapes) {
      int32_t k = -1;
      softdeca_blendshape_find_index(s.name.c_str(), &k);
      if (k < 0) continue;
      expect_near3(&avatar.blendshapes[3 * (static_cast<std::size_t>(k) * n + v)], apply(m, &s.deltas[3 * i], false), 1e-7,
                   mesh.name + " " + s.name + " vertex " + std::to_string(i));
    }
  }
}

bool has_unused(const AvatarFile& a, const std::string& mesh, const std::string& name, const std::string& reason_part) {
  for (const UnusedName& u : a.names_not_used)
    if (u.mesh == mesh && u.name == name && u.reason.find(reason_part) != std::string::npos) return true;
  return false;
}


std::vector<std::size_t> identity_order(std::size_t n) {
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  return order;
}

#define REQUIRE_FBX_FILES() \
  if (!fbx_files_supported()) GTEST_SKIP() << "built without assimp"
}  // namespace

TEST(AvatarFiles, GlbKeepsVertexOrderPlacesPartsAndFindsArkitShapes) {
  const TempDir dir("avatar-glb");
  const TestScene scene = avatar_scene();
  const AvatarFile a = read_avatar_file(dir.write("avatar.glb", softdeca::test::glb_bytes(scene)));
  EXPECT_EQ(a.format, "glTF 2.0");
  EXPECT_EQ(a.declared_metres_per_unit, 1.0);
  ASSERT_EQ(a.parts.size(), 2u);
  EXPECT_EQ(a.parts[0].name, "Head");
  EXPECT_EQ(a.parts[1].name, "Teeth");
  EXPECT_EQ(a.parts[1].first_vertex, 6u);
  ASSERT_EQ(a.left_out.size(), 1u);
  EXPECT_EQ(a.left_out[0].name, "Hair");
  EXPECT_EQ(a.left_out[0].reason, "no ARKit shape among its blendshapes");
  expect_part(a, a.parts[0], scene, scene.meshes[0], identity_order(6));
  expect_part(a, a.parts[1], scene, scene.meshes[1], identity_order(4));
  // Triangles as in the file, the second part's behind the first's.
  std::vector<std::int32_t> want = scene.meshes[0].triangles;
  for (const std::int32_t t : scene.meshes[1].triangles) want.push_back(t + 6);
  EXPECT_EQ(a.triangles, want);
  // Shapes: every ARKit shape under the rig's own name, per part; the rest listed, not used.
  EXPECT_EQ(a.shape_count(), 3u);
  ASSERT_EQ(a.shape_sources[shape("jawOpen")].size(), 2u);
  EXPECT_EQ(a.shape_sources[shape("jawOpen")][0].rig_name, "AK_07_JawOpen");
  EXPECT_EQ(a.shape_sources[shape("jawOpen")][1].part, "Teeth");
  EXPECT_EQ(a.shape_sources[shape("eyeBlinkLeft")][0].rig_name, "blendShape1.eyeBlinkLeft");
  EXPECT_EQ(a.shape_sources[shape("mouthSmileLeft")][0].rig_name, "mouthSmile_L");
  EXPECT_TRUE(a.shape_sources[shape("tongueOut")].empty());
  EXPECT_TRUE(has_unused(a, "Head", "eyeBlinkLeft_corrective", "no ARKit name"));
  EXPECT_TRUE(has_unused(a, "Hair", "hairWind", "no ARKit name"));
  // Shapes a part lacks are zeros there (the teeth do not blink).
  const std::size_t n = a.vertex_count();
  for (std::size_t v = 6; v < n; ++v) EXPECT_EQ(a.blendshapes[3 * (shape("eyeBlinkLeft") * n + v)], 0.0f);
  // The C ABI's view.
  const softdeca_avatar_mesh abi = a.abi_mesh();
  EXPECT_EQ(abi.vertex_count, 10u);
  EXPECT_EQ(abi.triangle_count, 12u);
  EXPECT_EQ(abi.blendshape_count, 52u);
}

TEST(AvatarFiles, FramesGoBackToEachPartsOwnCoordinates) {
  const TempDir dir("avatar-local");
  const TestScene scene = avatar_scene();
  const AvatarFile a = read_avatar_file(dir.write("avatar.glb", softdeca::test::glb_bytes(scene)));
  PartSpace space(a);
  const float* local = space.to_local(a.neutral.data());
  for (std::size_t p = 0; p < 2; ++p)
    for (std::size_t i = 0; i < a.parts[p].vertex_count; ++i)
      for (std::size_t c = 0; c < 3; ++c)
        EXPECT_NEAR(local[3 * (a.parts[p].first_vertex + i) + c], scene.meshes[p].vertices[3 * i + c], 1e-4);
  // A frame's motion goes back through the same transform: jawOpen in the teeth's own units.
  std::vector<float> frame = a.neutral;
  const std::size_t n = a.vertex_count(), jaw = shape("jawOpen");
  for (std::size_t i = 0; i < 3 * n; ++i) frame[i] += a.blendshapes[3 * jaw * n + i];
  local = space.to_local(frame.data());
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(local[3 * (6 + i) + c], scene.meshes[1].vertices[3 * i + c] + scene.meshes[1].shapes[0].deltas[3 * i + c], 1e-4);
  // The OBJ of a frame: every part's vertices in its own coordinates, an object per part.
  space.write_obj(dir.file("frame.obj"), a.neutral.data(), nullptr, "test");
  const ObjMesh obj = read_obj(dir.file("frame.obj"));
  ASSERT_EQ(obj.vertex_count(), n);
  EXPECT_NEAR(obj.vertices[3 * 6 + 1], 0.0f, 1e-4);
  EXPECT_EQ(obj.triangles, space.local_triangles());
}

TEST(AvatarFiles, VrmIsReadAsBinaryGltf) {
  const TempDir dir("avatar-vrm");
  const AvatarFile a = read_avatar_file(dir.write("avatar.vrm", softdeca::test::glb_bytes(avatar_scene())));
  EXPECT_EQ(a.format, "glTF 2.0");
  EXPECT_EQ(a.parts.size(), 2u);
}

TEST(AvatarFiles, FbxWeldsCornersBackAndTakesTheFullShapeOfAnInBetween) {
  REQUIRE_FBX_FILES();
  const TempDir dir("avatar-fbx");
  TestScene scene = avatar_scene();
  scene.fbx_unit_cm = 1;
  const AvatarFile a = read_avatar_file(dir.write("avatar.fbx", softdeca::test::fbx_bytes(scene)));
  EXPECT_EQ(a.format, "FBX");
  EXPECT_NEAR(a.declared_metres_per_unit, 0.01, 1e-12);
  EXPECT_NE(a.declared_unit.find("cm"), std::string::npos) << a.declared_unit;
  ASSERT_EQ(a.parts.size(), 2u);
  EXPECT_EQ(a.parts[0].name, "Head");
  ASSERT_EQ(a.left_out.size(), 1u);
  EXPECT_EQ(a.left_out[0].name, "Hair");
  // assimp reads a vertex per polygon corner; welded, each file vertex is there once, in the
  // order the polygons first use it.
  for (std::size_t p = 0; p < 2; ++p) {
    const TestMesh& mesh = scene.meshes[p];
    std::vector<std::size_t> order(mesh.vertices.size() / 3, SIZE_MAX);
    std::size_t next = 0;
    for (const std::int32_t t : mesh.triangles)
      if (order[static_cast<std::size_t>(t)] == SIZE_MAX) order[static_cast<std::size_t>(t)] = next++;
    expect_part(a, a.parts[p], scene, mesh, order);
    // The triangles are the file's, over the welded vertices.
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      EXPECT_EQ(static_cast<std::size_t>(a.triangles[3 * a.parts[p].first_triangle + t]) - a.parts[p].first_vertex,
                order[static_cast<std::size_t>(mesh.triangles[t])]);
  }
  // The in-between of mouthSmile_L (written first) is not the shape; the full target is.
  EXPECT_EQ(a.shape_sources[shape("mouthSmileLeft")][0].rig_name, "mouthSmile_L");
  EXPECT_TRUE(has_unused(a, "Head", "mouthSmile_L", "in-between"));
  EXPECT_EQ(a.vertex_order, "the FBX file's vertices in the order its polygons first use them");
}

TEST(AvatarFiles, AMirroringTransformTurnsTheTrianglesOverAndBack) {
  const TempDir dir("avatar-mirror");
  TestScene scene;
  scene.meshes = {head()};
  scene.meshes[0].scale[0] = -1;
  const AvatarFile a = read_avatar_file(dir.write("mirrored.glb", softdeca::test::glb_bytes(scene)));
  ASSERT_TRUE(a.parts[0].mirrored);
  EXPECT_EQ(a.triangles[1], scene.meshes[0].triangles[2]);
  EXPECT_EQ(a.triangles[2], scene.meshes[0].triangles[1]);
  EXPECT_EQ(PartSpace(a).local_triangles(), scene.meshes[0].triangles);
}

TEST(AvatarFiles, WeldingKeepsCornersApartThatAShapeMovesApart) {
  SourceMesh mesh;
  mesh.vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0};  // two triangles' corners, all shared by position
  mesh.triangles = {0, 1, 2, 3, 5, 4};
  mesh.shapes = {{"jawOpen", {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.5f, 0}}};  // the second triangle's top corner moves
  weld_corners(mesh);
  EXPECT_EQ(mesh.vertex_count(), 4u);
  EXPECT_EQ(mesh.triangles, (std::vector<std::int32_t>{0, 1, 2, 0, 3, 1}));
  EXPECT_EQ(mesh.shapes[0].deltas[3 * 3 + 1], 0.5f);
}

TEST(AvatarFiles, HostileFilesGetErrorsNamingTheFileAndMesh) {
  const TempDir dir("avatar-hostile");
  const std::string glb = softdeca::test::glb_bytes(avatar_scene());

  const std::string truncated = dir.write("truncated.glb", glb.substr(0, glb.size() / 2));
  EXPECT_NE(error_of(truncated).find(truncated), std::string::npos) << error_of(truncated);
  EXPECT_NE(error_of(dir.write("empty.glb", "")).find("is empty"), std::string::npos);
  const std::string garbage = dir.write("garbage.fbx", std::string(4096, '\x5a'));
  EXPECT_NE(error_of(garbage).find(garbage), std::string::npos) << error_of(garbage);
  EXPECT_NE(error_of(dir.write("mesh.stl", "solid")).find("not an avatar"), std::string::npos);
  EXPECT_NE(error_of(dir.file("missing.glb")).find("cannot open"), std::string::npos);

  TestScene nan = avatar_scene();
  nan.meshes[0].vertices[4] = std::numeric_limits<float>::quiet_NaN();
  const std::string nan_path = dir.write("nan.glb", softdeca::test::glb_bytes(nan));
  const std::string nan_error = error_of(nan_path);
  EXPECT_NE(nan_error.find(nan_path + ": mesh 'Head': vertex 1 is not finite"), std::string::npos) << nan_error;
  TestScene nan_shape = avatar_scene();
  nan_shape.meshes[1].shapes[0].deltas[7] = std::numeric_limits<float>::infinity();
  const std::string nan_shape_error = error_of(dir.write("nan_shape.glb", softdeca::test::glb_bytes(nan_shape)));
  EXPECT_NE(nan_shape_error.find("mesh 'Teeth': shape 'jawOpen': vertex 2 is not finite"), std::string::npos) << nan_shape_error;

  TestScene no_arkit;
  no_arkit.meshes = {hair()};
  const std::string no_arkit_error = error_of(dir.write("hair.glb", softdeca::test::glb_bytes(no_arkit)));
  EXPECT_NE(no_arkit_error.find("no mesh carries an ARKit blendshape: 'Hair' (no ARKit shape among its blendshapes)"),
            std::string::npos)
      << no_arkit_error;

  const std::string ok = dir.write("ok.glb", glb);
  ImportLimits small_file;
  small_file.max_file_bytes = 100;
  EXPECT_NE(error_of(ok, small_file).find("more than the 100"), std::string::npos);
  ImportLimits few_vertices;
  few_vertices.max_vertices = 5;
  const std::string too_many = error_of(ok, few_vertices);
  EXPECT_NE(too_many.find("mesh 'Head': 6 vertices, more than the 5"), std::string::npos) << too_many;
  ImportLimits few_in_all;
  few_in_all.max_vertices = 8;
  EXPECT_NE(error_of(ok, few_in_all).find("the meshes with ARKit shapes have more than the 8"), std::string::npos);
}

TEST(AvatarFiles, AShapeOfAnotherVertexCountIsRefused) {
  const TempDir dir("avatar-shape-size");
  TestScene scene = avatar_scene();
  scene.meshes[1].shapes[0].deltas.resize(9);  // 3 of the teeth's 4 vertices
  const std::string path = dir.write("short_shape.glb", softdeca::test::glb_bytes(scene));
  const std::string error = error_of(path);
  EXPECT_NE(error.find(path + ": mesh 'Teeth': shape 'jawOpen' has 3 vertices, the mesh 4"), std::string::npos) << error;
}

// FBX is scanned before assimp parses it (plugin/import/fbx_bounds.h).
namespace {
std::string binary_fbx(const std::vector<softdeca::test::files_detail::FbxNode>& top) {
  std::string out("Kaydara FBX Binary  \0\x1a\0", 23);
  softdeca::test::files_detail::append(out, std::uint32_t{7400});
  for (const auto& node : top) softdeca::test::files_detail::fbx_put(out, node);
  return out + std::string(13, '\0');
}

std::string scan_error(const std::string& bytes, const ImportLimits& limits = {}) {
  try {
    scan_fbx(bytes, "a.fbx", limits);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(FbxBounds, TheTestAvatarPassesAndItsConnectionsAreRead) {
  const FbxScan scan = scan_fbx(softdeca::test::fbx_bytes(avatar_scene()), "a.fbx", {});
  EXPECT_TRUE(scan.binary);
  EXPECT_EQ(scan.version, 7400u);
  EXPECT_GE(scan.depth, 3);
  EXPECT_GE(scan.connection_depth, 2u);  // a mesh's geometry under its model under the root
}

TEST(FbxBounds, DeepNestingLongChainsAndExpandingArraysAreRefusedBeforeAssimp) {
  using softdeca::test::files_detail::FbxNode;
  FbxNode deep{"Objects", {}, {}};
  FbxNode* at = &deep;
  for (int i = 0; i < 80; ++i) {
    at->children.push_back({"Model", {}, {}});
    at = &at->children.back();
  }
  EXPECT_NE(scan_error(binary_fbx({deep})).find("nested more than 64 deep"), std::string::npos);

  FbxNode chain{"Connections", {}, {}};
  for (std::int64_t i = 1; i <= 300; ++i)
    chain.children.push_back({"C", {softdeca::test::files_detail::fbx_string("OO"), softdeca::test::files_detail::fbx_long(i),
                                    softdeca::test::files_detail::fbx_long(i + 1)}, {}});
  EXPECT_NE(scan_error(binary_fbx({chain})).find("connected more than 256 deep"), std::string::npos);
  chain.children.push_back({"C", {softdeca::test::files_detail::fbx_string("OO"), softdeca::test::files_detail::fbx_long(301),
                                  softdeca::test::files_detail::fbx_long(1)}, {}});
  EXPECT_NE(scan_error(binary_fbx({chain})).find("in a cycle"), std::string::npos);

  // A zlib array that says it holds 300 million doubles (2.4 GB) in a file of a few bytes.
  std::string bomb;
  softdeca::test::files_detail::append(bomb, std::uint32_t{300000000});
  softdeca::test::files_detail::append(bomb, std::uint32_t{1});
  softdeca::test::files_detail::append(bomb, std::uint32_t{4});
  bomb += "abcd";
  const FbxNode vertices{"Vertices", {{'d', bomb}}, {}};
  EXPECT_NE(scan_error(binary_fbx({vertices})).find("would expand to 2.24 GiB, more than"), std::string::npos);

  std::string truncated = softdeca::test::fbx_bytes(avatar_scene());
  truncated.resize(truncated.size() / 2);
  EXPECT_NE(scan_error(truncated).find("not a readable FBX file"), std::string::npos);

  std::string ascii = "; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n}\n";
  for (int i = 0; i < 100; ++i) ascii += "A: {\n";
  EXPECT_NE(scan_error(ascii).find("nested more than 64 deep"), std::string::npos);
  std::string ascii_chain = "FBXHeaderExtension:  {\n}\nConnections:  {\n";
  for (int i = 1; i <= 300; ++i) ascii_chain += "\tC: \"OO\"," + std::to_string(i) + "," + std::to_string(i + 1) + "\n";
  EXPECT_NE(scan_error(ascii_chain + "}\n").find("connected more than 256 deep"), std::string::npos);
}
