// `softdeca fit` and `softdeca replay` of a user's own avatar end to end, on the runtime tests'
// synthetic bundle: the test head written as a user's glTF and FBX (centimetres, turned and
// moved by its node, beside a body part without ARKit shapes) is fitted and replayed, and its
// point caches, in the head's own coordinates, match the replay of the head in the template's
// topology; a fit folder refuses a changed mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "avatar_test_files.h"
#include "bundle/json.h"
#include "fit_folder.h"
#include "mesh_io.h"
#include "runtime_fixture.h"

using softdeca::test::TempDir;
using softdeca::test::TestMesh;
using softdeca::test::TestScene;

namespace {
constexpr float kCentimetres = 100;

// Frames x points x 3 of a PC2 file.
std::vector<std::vector<float>> read_pc2(const std::string& path) {
  const std::vector<char> bytes = rt::read_bytes(path);
  std::vector<std::vector<float>> frames;
  if (bytes.size() < 32) return frames;
  std::int32_t points = 0, count = 0;
  std::memcpy(&points, &bytes[16], 4);
  std::memcpy(&count, &bytes[28], 4);
  for (std::int32_t f = 0; f < count; ++f) {
    std::vector<float> frame(3 * static_cast<std::size_t>(points));
    std::memcpy(frame.data(), &bytes[32 + 12 * static_cast<std::size_t>(points) * static_cast<std::size_t>(f)], 12 * frame.size() / 3);
    frames.push_back(std::move(frame));
  }
  return frames;
}

// The test head as a user's avatar: its ARKit shapes under a rig's names, in centimetres, placed
// by its node; a body the shapes do not move as a second mesh.
TestScene user_scene(const rt::Head& h) {
  TestMesh head;
  head.name = "Head";
  for (const float v : h.neutral) head.vertices.push_back(kCentimetres * v);
  head.triangles = h.triangles;
  const std::size_t n = h.vertices();
  for (uint32_t k = 0; k < 52; ++k) {
    softdeca::test::TestShape shape{std::string("blendShape1.") + softdeca_blendshape_name(k), {}, {}};
    for (std::size_t i = 0; i < 3 * n; ++i) shape.deltas.push_back(kCentimetres * h.blendshapes[3 * k * n + i]);
    head.shapes.push_back(std::move(shape));
  }
  head.rotation_y_degrees = 30;
  head.translation[1] = 150;
  TestMesh body;
  body.name = "Body";
  for (int b = 0; b < 8; ++b) body.vertices.insert(body.vertices.end(), {(b & 1) ? 20.f : -20.f, (b & 2) ? 100.f : 60.f, (b & 4) ? 10.f : -10.f});
  body.triangles = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};
  body.shapes = {{"Breathe", std::vector<float>(24, 0.1f), {}}};
  TestScene scene;
  scene.meshes = {head, body};
  return scene;
}

class CliFit : public ::testing::Test {
 protected:
  void SetUp() override {
    if (rt::data_dir().empty()) GTEST_SKIP() << "SOFTDECA_TEST_DATA is not set (ctest's runtime_test_data fixture)";
    head_ = rt::Head::load();
    bundle_ = rt::data_dir() + "/bundle";
    take_ = rt::data_dir() + "/take.csv";
  }
  // Runs the command line; its output goes to <dir>/<log>.
  int softdeca(const std::string& args, const std::string& log) const {
    return std::system(("'" SOFTDECA_CLI "' " + args + " > '" + dir_.file(log) + "' 2>&1").c_str());
  }
  std::string log(const std::string& name) const {
    const std::vector<char> text = rt::read_bytes(dir_.file(name));
    return std::string(text.begin(), text.end());
  }
  // The replay of the head in the template's topology, in centimetres.
  std::vector<std::vector<float>> template_replay(const std::string& model) {
    if (!replayed_) {
      EXPECT_EQ(softdeca("replay '" + take_ + "' --bundle '" + bundle_ + "' --avatar '" + rt::data_dir() + "/avatar' --frames 12 " +
                             "--models linear,softdeca --out '" + dir_.file("template") + "'",
                         "template.log"),
                0)
          << log("template.log");
      replayed_ = true;
    }
    auto frames = read_pc2(dir_.file("template/" + model + ".pc2"));
    for (auto& f : frames)
      for (float& v : f) v *= kCentimetres;
    return frames;
  }

  TempDir dir_{"cli-fit"};
  rt::Head head_;
  std::string bundle_, take_;
  bool replayed_ = false;
};

float max_difference(const std::vector<std::vector<float>>& a, const std::vector<std::vector<float>>& b) {
  float worst = a.size() == b.size() && !a.empty() ? 0.0f : INFINITY;
  for (std::size_t f = 0; f < std::min(a.size(), b.size()); ++f) {
    if (a[f].size() != b[f].size()) return INFINITY;
    for (std::size_t i = 0; i < a[f].size(); ++i) worst = std::max(worst, std::abs(a[f][i] - b[f][i]));
  }
  return worst;
}
}  // namespace

TEST_F(CliFit, AFittedGltfReplaysAsItsHeadInTheTemplatesTopology) {
  const std::string glb = dir_.write("user.glb", softdeca::test::glb_bytes(user_scene(head_)));
  // The synthetic shapes are random: no unit to read off them.
  ASSERT_EQ(softdeca("fit '" + glb + "' --bundle '" + bundle_ + "' --out '" + dir_.file("fit") + "' --metres-per-unit 0.01", "fit.log"), 0)
      << log("fit.log");
  EXPECT_NE(log("fit.log").find("left out  Body"), std::string::npos) << log("fit.log");
  for (const char* file : {"avatar.fit", "fit.json", "fit.png"}) EXPECT_TRUE(std::filesystem::exists(dir_.file("fit/") + file)) << file;
  const std::vector<char> json = rt::read_bytes(dir_.file("fit/fit.json"));
  const softdeca::runtime::Json report = softdeca::runtime::Json::parse(std::string(json.begin(), json.end()));
  EXPECT_EQ(report.at("parts", "").array("").size(), 1u);
  EXPECT_EQ(report.at("left_out", "").array("")[0].at("name", "").string(""), "Body");
  EXPECT_EQ(report.at("shapes", "").at("jawOpen", "").at("Head", "").string(""), "blendShape1.jawOpen");
  EXPECT_TRUE(report.at("fit", "").has("face_residual_mm_max"));

  ASSERT_EQ(softdeca("replay '" + take_ + "' --bundle '" + bundle_ + "' --avatar '" + dir_.file("fit") + "' --frames 12 --out '" +
                         dir_.file("fitted") + "'",
                     "fitted.log"),
            0)
      << log("fitted.log");
  // The head's own coordinates (centimetres, before its node's transform), its own order.
  const softdeca::cli::ObjMesh neutral = softdeca::cli::read_obj(dir_.file("fitted/neutral.obj"));
  ASSERT_EQ(neutral.vertex_count(), head_.vertices());
  for (std::size_t i = 0; i < neutral.vertices.size(); ++i) EXPECT_NEAR(neutral.vertices[i], kCentimetres * head_.neutral[i], 1e-3);
  // The fitted avatar's own linear blend is its rig's; SoftDECA's correction comes through the fit.
  EXPECT_LT(max_difference(read_pc2(dir_.file("fitted/linear.pc2")), template_replay("linear")), 1e-3f);
  EXPECT_LT(max_difference(read_pc2(dir_.file("fitted/softdeca.pc2")), template_replay("softdeca")), 1e-2f);
  EXPECT_EQ(read_pc2(dir_.file("fitted/sparse.pc2")).size(), 12u);

  // A fit folder refuses a mesh that changed since.
  TestScene changed = user_scene(head_);
  changed.meshes[0].vertices[0] += 0.5f;
  dir_.write("user.glb", softdeca::test::glb_bytes(changed));
  EXPECT_NE(softdeca("replay '" + take_ + "' --bundle '" + bundle_ + "' --avatar '" + dir_.file("fit") + "' --frames 2 --out '" +
                         dir_.file("changed") + "'",
                     "changed.log"),
            0);
  EXPECT_NE(log("changed.log").find("is not the mesh fitted in"), std::string::npos) << log("changed.log");
}

TEST_F(CliFit, AnFbxIsFittedOnTheSpotAndWrittenInItsWeldedOrder) {
  if (!softdeca::avatar_import::fbx_files_supported()) GTEST_SKIP() << "built without assimp";
  const std::string fbx = dir_.write("user.fbx", softdeca::test::fbx_bytes(user_scene(head_)));
  ASSERT_EQ(softdeca("replay '" + take_ + "' --bundle '" + bundle_ + "' --avatar '" + fbx + "' --metres-per-unit 0.01 --frames 12 " +
                         "--models linear --out '" + dir_.file("fbx") + "'",
                     "fbx.log"),
            0)
      << log("fbx.log");
  EXPECT_NE(log("fbx.log").find("fitting " + fbx), std::string::npos);
  // The file's vertices in the order its polygons first use them.
  std::vector<std::size_t> order(head_.vertices(), SIZE_MAX);
  std::size_t next = 0;
  for (const std::int32_t t : head_.triangles)
    if (order[static_cast<std::size_t>(t)] == SIZE_MAX) order[static_cast<std::size_t>(t)] = next++;
  const auto fitted = read_pc2(dir_.file("fbx/linear.pc2"));
  const auto want = template_replay("linear");
  ASSERT_EQ(fitted.size(), want.size());
  float worst = 0;
  for (std::size_t f = 0; f < want.size(); ++f)
    for (std::size_t v = 0; v < order.size(); ++v)
      for (std::size_t c = 0; c < 3; ++c)
        if (order[v] != SIZE_MAX) worst = std::max(worst, std::abs(fitted[f][3 * order[v] + c] - want[f][3 * v + c]));
  EXPECT_LT(worst, 1e-3f);
}
