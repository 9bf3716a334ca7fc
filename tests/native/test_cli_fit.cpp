// `softdeca fit` and `softdeca replay` of a user's own avatar end to end, on the runtime tests'
// synthetic bundle: the test head written as a user's glTF and FBX (centimetres, turned and
// moved by its node, beside a body part without ARKit shapes) is fitted and replayed, and its
// point caches, in the head's own coordinates, match the replay of the head in the template's
// topology; a fit folder refuses a changed mesh; a poor fit is refused with its reason unless
// kept on request, marked poor. The fit folder is written whole: two fits at once into one folder
// leave one of them, a link in it is not written through, a failed write leaves the previous
// folder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
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
    softdeca::test::TestShape shape{std::string("blendShape1.") + softdeca_blendshape_get_name(k), {}, {}};
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
  const softdeca::bundle::Json report = softdeca::bundle::Json::parse(std::string(json.begin(), json.end()));
  EXPECT_EQ(report.at("parts", "").array("").size(), 1u);
  EXPECT_EQ(report.at("left_out", "").array("")[0].at("name", "").string(""), "Body");
  EXPECT_EQ(report.at("shapes", "").at("jawOpen", "").at("Head", "").string(""), "blendShape1.jawOpen");
  EXPECT_TRUE(report.at("fit", "").has("face_residual_mm_max"));
  EXPECT_TRUE(report.at("fit", "").at("quality", "").at("passed", "").boolean(""));
  EXPECT_FALSE(report.at("poor_fit", "").boolean(""));

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

TEST_F(CliFit, APoorFitIsRefusedWithItsReasonUnlessKept) {
  // A shell around the head, 1.5 times its size and moved by the same shapes: the template fits
  // the head and covers a patch of the face the shapes move.
  TestScene scene = user_scene(head_);
  TestMesh shell = scene.meshes[0];
  shell.name = "Shell";
  for (float& x : shell.vertices) x *= 1.5f;
  for (softdeca::test::TestShape& s : shell.shapes)
    for (float& x : s.deltas) x *= 1.5f;
  scene.meshes.push_back(shell);
  const std::string glb = dir_.write("shell.glb", softdeca::test::glb_bytes(scene));
  const std::string fit = "fit '" + glb + "' --bundle '" + bundle_ + "' --metres-per-unit 0.01 --out '";
  EXPECT_NE(softdeca(fit + dir_.file("poor") + "'", "poor.log"), 0);
  const std::string refused = log("poor.log");
  EXPECT_NE(refused.find("the fit is poor (face_coverage)"), std::string::npos) << refused;
  EXPECT_NE(refused.find("at least 70 %"), std::string::npos) << refused;
  EXPECT_NE(refused.find("Likely cause"), std::string::npos) << refused;
  EXPECT_NE(refused.find("--keep-poor-fit"), std::string::npos) << refused;
  EXPECT_FALSE(std::filesystem::exists(dir_.file("poor/avatar.fit")));
  EXPECT_FALSE(std::filesystem::exists(dir_.file("poor/fit.json")));

  ASSERT_EQ(softdeca(fit + dir_.file("kept") + "' --keep-poor-fit", "kept.log"), 0) << log("kept.log");
  EXPECT_NE(log("kept.log").find("keeping a poor fit (face_coverage)"), std::string::npos) << log("kept.log");
  EXPECT_TRUE(std::filesystem::exists(dir_.file("kept/avatar.fit")));
  const std::vector<char> json = rt::read_bytes(dir_.file("kept/fit.json"));
  const softdeca::bundle::Json report = softdeca::bundle::Json::parse(std::string(json.begin(), json.end()));
  EXPECT_TRUE(report.at("poor_fit", "").boolean(""));
  const softdeca::bundle::Json& quality = report.at("fit", "").at("quality", "");
  EXPECT_FALSE(quality.at("passed", "").boolean(""));
  EXPECT_EQ(quality.at("failed_measure", "").string(""), "face_coverage");
  EXPECT_LT(report.at("fit", "").at("face_coverage", "").number(""), 0.7);
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

namespace {
namespace fs = std::filesystem;

std::string text_of(const std::string& path) {
  const std::vector<char> bytes = rt::read_bytes(path);
  return std::string(bytes.begin(), bytes.end());
}

// The fit folder's files as they are now.
std::vector<std::string> folder_files(const std::string& dir) {
  std::vector<std::string> out;
  for (const char* name : {"avatar.fit", "fit.json", "fit.png"}) out.push_back(text_of(dir + "/" + name));
  return out;
}

// What `softdeca fit` writes, written by several at once, links in the folder, failed writes:
// the test avatar folder (the runtime tests' head), no assimp needed.
class CliFitFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    if (rt::data_dir().empty()) GTEST_SKIP() << "SOFTDECA_TEST_DATA is not set (ctest's runtime_test_data fixture)";
    bundle_ = rt::data_dir() + "/bundle";
    // The head as two avatars: as made, and with one vertex moved a tenth of a millimetre.
    fs::copy(rt::data_dir() + "/avatar", dir_.file("a"), fs::copy_options::recursive);
    fs::copy(rt::data_dir() + "/avatar", dir_.file("b"), fs::copy_options::recursive);
    softdeca::cli::ObjMesh moved = softdeca::cli::read_obj(dir_.file("b/neutral.obj"));
    moved.vertices[0] += 1e-4f;
    softdeca::cli::write_obj(dir_.file("b/neutral.obj"), moved.vertices.data(), moved.vertex_count(), nullptr,
                             moved.triangles.data(), moved.triangles.size() / 3, "a vertex moved");
  }
  // The command line `softdeca fit MESH --out OUT` (the synthetic shapes give no unit: metres).
  std::string fit_command(const std::string& mesh, const std::string& out, const std::string& log) const {
    return "'" SOFTDECA_CLI "' fit '" + dir_.file(mesh) + "' --bundle '" + bundle_ + "' --out '" + dir_.file(out) +
           "' --metres-per-unit 1 > '" + dir_.file(log) + "' 2>&1";
  }
  int fit(const std::string& mesh, const std::string& out, const std::string& log) const {
    return std::system(fit_command(mesh, out, log).c_str());
  }
  // The fit folder is one fit's: the mesh fit.json names (checked against its SHA-256) is the
  // one avatar.fit was made for (the library checks its own hash of it).
  void expect_one_fit(const std::string& out) const {
    const softdeca::cli::AvatarFile mesh = softdeca::cli::read_fitted_mesh(dir_.file(out));
    rt::ModelPtr model;
    ASSERT_EQ(softdeca_model_load(bundle_.c_str(), nullptr, &model.p), SOFTDECA_OK) << softdeca_last_error();
    softdeca_avatar_fit* loaded = nullptr;
    ASSERT_EQ(softdeca_avatar_fit_load(model.p, softdeca::cli::fit_file(dir_.file(out)).c_str(), &loaded), SOFTDECA_OK)
        << softdeca_last_error();
    const softdeca_avatar_mesh abi = mesh.abi_mesh();
    rt::AvatarPtr avatar;
    EXPECT_EQ(rt::create_on_fit(model.p, loaded, &abi, 1, 0, &avatar.p), SOFTDECA_OK) << softdeca_last_error();
    softdeca_avatar_fit_destroy(loaded);
  }
  // Nothing but what the test made beside the fit folders: no temporary folder is left.
  void expect_no_temporary_folder() const {
    for (const auto& e : fs::directory_iterator(dir_.dir))
      EXPECT_NE(e.path().filename().string().front(), '.') << e.path() << " is left";
  }

  TempDir dir_{"cli-fit-folder"};
  std::string bundle_;
};
}  // namespace

TEST_F(CliFitFolder, TwoFitsAtOnceIntoOneFolderLeaveOneWholeFit) {
  for (int round = 0; round < 2; ++round) {
    const std::string both = fit_command("a", "out", "a.log") + " & a=$!; " + fit_command("b", "out", "b.log") +
                             " & b=$!; wait $a; ra=$?; wait $b; rb=$?; exit $((ra | rb))";
    ASSERT_EQ(std::system(both.c_str()), 0) << text_of(dir_.file("a.log")) << text_of(dir_.file("b.log"));
    expect_one_fit("out");
  }
  expect_no_temporary_folder();
}

TEST_F(CliFitFolder, ALinkInAFitFolderIsReplacedNotWrittenThrough) {
  ASSERT_EQ(fit("a", "out", "first.log"), 0) << text_of(dir_.file("first.log"));
  const std::string outside = dir_.write("outside.txt", "not the fit's");
  for (const char* name : {"fit.png", "fit.json"}) {
    fs::remove(dir_.file(std::string("out/") + name));
    fs::create_symlink(outside, dir_.file(std::string("out/") + name));
  }
  ASSERT_EQ(fit("b", "out", "second.log"), 0) << text_of(dir_.file("second.log"));
  EXPECT_EQ(text_of(outside), "not the fit's");
  for (const char* name : {"avatar.fit", "fit.png", "fit.json"})
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir_.file(std::string("out/") + name)))) << name;
  expect_one_fit("out");
  expect_no_temporary_folder();
}

TEST_F(CliFitFolder, AFailedWriteLeavesThePreviousFolderAndNoTemporaryFolder) {
  ASSERT_EQ(fit("a", "out", "first.log"), 0) << text_of(dir_.file("first.log"));
  const std::vector<std::string> before = folder_files(dir_.file("out"));
  ASSERT_LT(before[0].size(), 500000u) << "avatar.fit fits under the limit below";
  ASSERT_GT(before[2].size(), 1300000u) << "fit.png does not";
  // A file size limit of 600 kB (sh counts 512-byte blocks) cuts fit.png short, as a full disk would.
  const std::string limited = "trap '' XFSZ; ulimit -f 1200; " + fit_command("b", "out", "limited.log");
  EXPECT_NE(std::system(limited.c_str()), 0);
  EXPECT_NE(text_of(dir_.file("limited.log")).find("could not save"), std::string::npos) << text_of(dir_.file("limited.log"));
  EXPECT_EQ(folder_files(dir_.file("out")), before);
  expect_no_temporary_folder();

  // A folder holding other files is not replaced.
  dir_.write("other/notes.txt", "mine");
  EXPECT_NE(fit("a", "other", "other.log"), 0);
  EXPECT_NE(text_of(dir_.file("other.log")).find("holds notes.txt, which is not a fit folder's"), std::string::npos)
      << text_of(dir_.file("other.log"));
  EXPECT_EQ(text_of(dir_.file("other/notes.txt")), "mine");
  EXPECT_EQ(fs::directory_iterator(dir_.file("other"))->path().filename(), "notes.txt");
  expect_no_temporary_folder();
}

TEST_F(CliFitFolder, AUnitTheFitCouldNotLoadIsRefusedBeforeFitting) {
  const std::string command = "'" SOFTDECA_CLI "' fit '" + dir_.file("a") + "' --bundle '" + bundle_ + "' --out '" +
                              dir_.file("out") + "' --metres-per-unit 1e-300 > '" + dir_.file("unit.log") + "' 2>&1";
  EXPECT_NE(std::system(command.c_str()), 0);
  EXPECT_NE(text_of(dir_.file("unit.log")).find("--metres-per-unit must be 0 (read off the shapes) or 1e-06 to 1000"),
            std::string::npos)
      << text_of(dir_.file("unit.log"));
  EXPECT_FALSE(fs::exists(dir_.file("out")));
}
