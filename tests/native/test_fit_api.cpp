// Fitting a user's avatar through the C ABI on the runtime tests' synthetic bundle: the head
// shuffled, in centimetres and inside a body is fitted, saved, loaded and animated; what the
// embedding does not hold moves exactly as the rig; a fit that leaves most of the face uncovered
// is judged poor in its report; hostile meshes and fit files get errors: a saved fit with any bit
// flipped, or with values no fit holds under a matching checksum, is refused, and saves from many
// threads to one path always leave a fit that loads.
// Kept whole: every case runs on one fixture (the bundle and the user's head), built once.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numeric>
#include <random>
#include <thread>

#include "api/runtime_handles.h"
#include "fit/fit_file.h"

#include "bundle/json.h"
#include "runtime_fixture.h"

namespace {

struct FitPtr {
  softdeca_avatar_fit* p = nullptr;
  ~FitPtr() { softdeca_avatar_fit_destroy(p); }
};

// The synthetic head as a user's avatar: vertices shuffled, centimetres, and a "body" (a box
// no shape moves) appended as a separate part.
struct UserAvatar {
  std::vector<float> neutral, deltas;
  std::vector<int32_t> triangles;
  std::vector<uint32_t> head_of;  // avatar vertex -> head vertex (body: ~0u)
  softdeca_avatar_mesh mesh{};

  explicit UserAvatar(const rt::Head& h) {
    const std::size_t n = h.vertices();
    std::vector<uint32_t> perm(n);
    std::iota(perm.begin(), perm.end(), 0u);
    std::shuffle(perm.begin(), perm.end(), std::mt19937(7));
    std::vector<uint32_t> where(n);
    for (std::size_t i = 0; i < n; ++i) where[perm[i]] = static_cast<uint32_t>(i);
    const std::size_t body = 8, total = n + body;
    neutral.resize(total * 3);
    deltas.assign(52 * total * 3, 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) neutral[3 * i + c] = 100.0f * h.neutral[3 * perm[i] + c];
      for (std::size_t s = 0; s < 52; ++s)
        for (int c = 0; c < 3; ++c) deltas[(s * total + i) * 3 + c] = 100.0f * h.blendshapes[(s * n + perm[i]) * 3 + c];
      head_of.push_back(perm[i]);
    }
    for (std::size_t b = 0; b < body; ++b) {  // a box 40 cm below the head
      neutral[3 * (n + b)] = (b & 1) ? 20.0f : -20.0f;
      neutral[3 * (n + b) + 1] = (b & 2) ? -40.0f : -80.0f;
      neutral[3 * (n + b) + 2] = (b & 4) ? 10.0f : -10.0f;
      head_of.push_back(~0u);
    }
    for (int32_t v : h.triangles) triangles.push_back(static_cast<int32_t>(where[static_cast<std::size_t>(v)]));
    const int32_t box[] = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};
    for (int32_t v : box) triangles.push_back(static_cast<int32_t>(n) + v);
    describe();
  }
  void describe() {
    mesh = {};
    mesh.struct_size = sizeof mesh;
    mesh.neutral = neutral.data();
    mesh.vertex_count = static_cast<uint32_t>(neutral.size() / 3);
    mesh.triangles = triangles.data();
    mesh.triangle_count = static_cast<uint32_t>(triangles.size() / 3);
    mesh.blendshapes = deltas.data();
    mesh.blendshape_count = 52;
  }
  std::size_t vertices() const { return neutral.size() / 3; }
};

class FitApi : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_TEST_DATA();
    head_ = rt::Head::load();
    ASSERT_EQ(softdeca_model_load((rt::data_dir() + "/bundle").c_str(), nullptr, &model_.p), SOFTDECA_OK)
        << softdeca_last_error();
    options_.struct_size = sizeof options_;
    ASSERT_EQ(softdeca_fit_options_init(&options_), SOFTDECA_OK);
    options_.metres_per_unit = 0.01;  // the synthetic shapes are random: no unit to read off them
  }
  softdeca_status fit(const softdeca_avatar_mesh& mesh, FitPtr& out) {
    return softdeca_avatar_fit_create(model_.p, &mesh, &options_, &out.p);
  }
  std::string report(const FitPtr& f) {
    uint32_t length = 0;
    softdeca_avatar_fit_get_report(f.p, nullptr, 0, &length);
    std::string text(length + 1, '\0');
    EXPECT_EQ(softdeca_avatar_fit_get_report(f.p, text.data(), length + 1, &length), SOFTDECA_OK);
    text.resize(length);
    return text;
  }
  // A fresh folder for this test's files, removed at the end.
  std::filesystem::path folder(const std::string& name) {
    folder_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
    return folder_;
  }
  void TearDown() override {
    if (!folder_.empty()) std::filesystem::remove_all(folder_);
  }
  // The user's avatar fitted into `f` and saved at `path`.
  void fit_and_save(FitPtr& f, const std::filesystem::path& path) {
    UserAvatar user(head_);
    ASSERT_EQ(fit(user.mesh, f), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_avatar_fit_save(f.p, path.string().c_str()), SOFTDECA_OK) << softdeca_last_error();
  }
  // Loads and drops a fit; softdeca_last_error() then tells why it was refused.
  softdeca_status load(const std::filesystem::path& path) {
    softdeca_avatar_fit* g = nullptr;
    const softdeca_status s = softdeca_avatar_fit_load(model_.p, path.string().c_str(), &g);
    if (g) softdeca_avatar_fit_destroy(g);
    return s;
  }
  rt::Head head_;
  rt::ModelPtr model_;
  softdeca_fit_options options_{};
  std::filesystem::path folder_;
};

void write_file(const std::filesystem::path& path, const std::vector<char>& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::string> entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST_F(FitApi, FitsSavesLoadsAndAnimatesTheUsersOwnMesh) {
  UserAvatar user(head_);
  FitPtr f;
  ASSERT_EQ(fit(user.mesh, f), SOFTDECA_OK) << softdeca_last_error();
  const std::string r = report(f);
  EXPECT_NE(r.find("\"metres_per_unit\": 0.01"), std::string::npos) << r;
  EXPECT_NE(r.find("\"face_residual_mm_mean\""), std::string::npos) << r;

  const auto path = std::filesystem::temp_directory_path() / "softdeca-test.fit";
  ASSERT_EQ(softdeca_avatar_fit_save(f.p, path.string().c_str()), SOFTDECA_OK) << softdeca_last_error();
  FitPtr loaded;
  ASSERT_EQ(softdeca_avatar_fit_load(model_.p, path.string().c_str(), &loaded.p), SOFTDECA_OK) << softdeca_last_error();
  EXPECT_EQ(report(loaded), r);

  rt::AvatarPtr a;
  ASSERT_EQ(rt::create_on_fit(model_.p, loaded.p, &user.mesh, 1, SOFTDECA_PRECISION_HALF, &a.p), SOFTDECA_OK)
      << softdeca_last_error();
  ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK) << softdeca_last_error();
  rt::Buffers physics(user.vertices()), linear(user.vertices());
  std::vector<float> w(52, 0.4f);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(a.p, w.data(), 52, &physics.out), SOFTDECA_OK) << softdeca_last_error();
  ASSERT_EQ(softdeca_avatar_evaluate_linear(a.p, w.data(), 52, &linear.out), SOFTDECA_OK) << softdeca_last_error();
  // The linear output is the avatar's own blend, vertex for vertex.
  for (std::size_t v = 0; v < user.vertices(); ++v)
    for (int c = 0; c < 3; ++c) {
      float blend = user.neutral[3 * v + c];
      for (std::size_t s = 0; s < 52; ++s) blend += w[s] * user.deltas[(s * user.vertices() + v) * 3 + c];
      ASSERT_NEAR(linear.vertices[3 * v + c], blend, 1e-4f) << v;
    }
  // The body no shape moves and the embedding does not reach is left exactly as the rig has it.
  double moved = 0;
  for (std::size_t v = 0; v < user.vertices(); ++v)
    for (int c = 0; c < 3; ++c) {
      const float d = physics.vertices[3 * v + c] - linear.vertices[3 * v + c];
      if (user.head_of[v] == ~0u) {
        EXPECT_EQ(d, 0.0f) << "body vertex " << v;
      }
      moved = std::max(moved, static_cast<double>(std::fabs(d)));
    }
  EXPECT_GT(moved, 0.0) << "the physics' correction reaches the avatar";
  std::filesystem::remove(path);
}

// On a bundle at SoftDECA's closed-form start (DT at identity) a fitted avatar's frame, with the
// dynamics off, contracts the vertex stages carried onto its own vertices at prepare; it is the
// registered template's whole frame carried (what a frame with the dynamics runs, and from rest
// that frame is the static one), to float rounding, at the defaults and with the physics at
// prepare's offset.
TEST_F(FitApi, AFittedAvatarsCarriedFrameIsItsWholeFrameCarried) {
  rt::ModelPtr closed;
  ASSERT_EQ(softdeca_model_load((rt::data_dir() + "/bundle_closed_form").c_str(), nullptr, &closed.p), SOFTDECA_OK)
      << softdeca_last_error();
  UserAvatar user(head_);
  FitPtr f;
  ASSERT_EQ(softdeca_avatar_fit_create(closed.p, &user.mesh, &options_, &f.p), SOFTDECA_OK) << softdeca_last_error();
  rt::AvatarPtr a;
  ASSERT_EQ(rt::create_on_fit(closed.p, f.p, &user.mesh, 1, SOFTDECA_PRECISION_FLOAT, &a.p), SOFTDECA_OK)
      << softdeca_last_error();
  rt::at_defaults_and_a_rest_offset(closed.p, a.p, 6, [&](const std::vector<float>& w, const std::string& what) {
    rt::Buffers carried(user.vertices()), whole(user.vertices()), linear(user.vertices());
    ASSERT_EQ(softdeca_avatar_set_dynamics(a.p, SOFTDECA_FALSE), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_evaluate_weights(a.p, w.data(), 52, &carried.out), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_avatar_set_dynamics(a.p, SOFTDECA_TRUE), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_reset_dynamics(a.p), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_evaluate_weights(a.p, w.data(), 52, &whole.out), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_avatar_evaluate_linear(a.p, w.data(), 52, &linear.out), SOFTDECA_OK);
    double worst = 0, moved = 0;
    for (std::size_t i = 0; i < carried.vertices.size(); ++i) {
      worst = std::max(worst, double(std::fabs(carried.vertices[i] - whole.vertices[i])));
      moved = std::max(moved, double(std::fabs(carried.vertices[i] - linear.vertices[i])));
    }
    // centimetres: float rounding of coordinates of tens of cm, corrections of tenths of a mm
    EXPECT_LT(worst, 1e-4) << what;
    EXPECT_GT(moved, 1e-3) << "the correction reaches the avatar";
  });
}

double number(const softdeca::bundle::Json& report, const std::string& name) { return report.at(name, "report").number(name); }

// The user's avatar with a shell around its head: a copy 1.5 times its size, moved by the same
// shapes (scaled alike). The template fits the head inside and lies on the avatar everywhere,
// but the face the shapes move is the shell's too: the template covers a patch of it, as a
// template squeezed into part of a face does.
UserAvatar with_shell(const UserAvatar& user, std::size_t head_vertices) {
  constexpr float kScale = 1.5f;
  const std::size_t m = user.vertices(), total = m + head_vertices;
  UserAvatar out = user;
  out.neutral.resize(3 * total);
  for (std::size_t i = 0; i < 3 * head_vertices; ++i) out.neutral[3 * m + i] = kScale * user.neutral[i];
  out.deltas.assign(52 * total * 3, 0.0f);
  for (std::size_t k = 0; k < 52; ++k)
    for (std::size_t i = 0; i < 3 * m; ++i) {
      out.deltas[k * total * 3 + i] = user.deltas[k * m * 3 + i];
      if (i < 3 * head_vertices) out.deltas[(k * total + m) * 3 + i] = kScale * user.deltas[k * m * 3 + i];
    }
  for (std::size_t f = 0; f + 2 < user.triangles.size(); f += 3)
    if (static_cast<std::size_t>(std::max({user.triangles[f], user.triangles[f + 1], user.triangles[f + 2]})) < head_vertices)
      for (int c = 0; c < 3; ++c) out.triangles.push_back(static_cast<int32_t>(m) + user.triangles[f + static_cast<std::size_t>(c)]);
  out.head_of.resize(total, ~0u);
  out.describe();
  return out;
}

TEST_F(FitApi, TheReportJudgesTheFitFromBothSides) {
  UserAvatar user(head_);
  FitPtr good;
  ASSERT_EQ(fit(user.mesh, good), SOFTDECA_OK) << softdeca_last_error();
  const auto g = softdeca::bundle::Json::parse(report(good));
  const softdeca::bundle::Json& verdict = g.at("quality", "report");
  EXPECT_TRUE(verdict.at("passed", "quality").boolean("passed")) << report(good);
  EXPECT_EQ(verdict.at("failed_measure", "quality").string("failed_measure"), "");
  EXPECT_EQ(verdict.at("reason", "quality").string("reason"), "");
  EXPECT_GT(number(g, "face_coverage"), 0.95) << report(good);
  EXPECT_LT(number(g, "avatar_to_template_mm_median"), 0.5) << report(good);
  EXPECT_LE(number(g, "avatar_to_template_mm_median"), number(g, "avatar_to_template_mm_p90"));
  EXPECT_LE(number(g, "avatar_to_template_mm_p90"), number(g, "avatar_to_template_mm_max"));
  EXPECT_NEAR(number(g, "template_scale"), 1.0, 0.05) << report(good);
  EXPECT_GT(number(g, "face_coverage_vertices"), 0.0);

  // Every point of the template lies on the avatar (the one-way residual is as good as the
  // head's own), yet half the face is uncovered: the fit is still made, for the host to
  // inspect, and its report calls it poor, naming the measure, the bound and the likely cause.
  const UserAvatar shell = with_shell(user, head_.vertices());
  FitPtr poor;
  ASSERT_EQ(fit(shell.mesh, poor), SOFTDECA_OK) << softdeca_last_error();
  const auto p = softdeca::bundle::Json::parse(report(poor));
  EXPECT_LT(number(p, "face_residual_mm_mean"), 0.5) << report(poor);
  const softdeca::bundle::Json& refused = p.at("quality", "report");
  EXPECT_FALSE(refused.at("passed", "quality").boolean("passed")) << report(poor);
  EXPECT_EQ(refused.at("failed_measure", "quality").string("failed_measure"), "face_coverage") << report(poor);
  const std::string reason = refused.at("reason", "quality").string("reason");
  EXPECT_NE(reason.find("covers"), std::string::npos) << reason;
  EXPECT_NE(reason.find("at least 70 %"), std::string::npos) << reason;
  EXPECT_NE(reason.find("squeezed"), std::string::npos) << reason;
  EXPECT_NE(reason.find("0.01 m"), std::string::npos) << "names the unit the fit took: " << reason;
  const softdeca::bundle::Json& bounds = refused.at("bounds", "quality");
  EXPECT_EQ(bounds.at("face_coverage_min", "bounds").number("face_coverage_min"), 0.7);
  EXPECT_EQ(bounds.at("covered_mm", "bounds").number("covered_mm"), 3.0);
  EXPECT_LT(number(p, "face_coverage"), 0.7);
  EXPECT_GT(number(p, "avatar_to_template_mm_median"), 10.0);
  EXPECT_LT(number(p, "template_scale"), bounds.at("template_scale_min", "bounds").number("template_scale_min"));
}

TEST_F(FitApi, AFittedAvatarTakesMapsPerAvatarElement) {
  UserAvatar user(head_);
  FitPtr f;
  ASSERT_EQ(fit(user.mesh, f), SOFTDECA_OK) << softdeca_last_error();
  rt::AvatarPtr a;
  ASSERT_EQ(rt::create_on_fit(model_.p, f.p, &user.mesh, 1, SOFTDECA_PRECISION_FLOAT, &a.p), SOFTDECA_OK);
  softdeca_parameter_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(softdeca_model_get_parameter_info(model_.p, 0, &info), SOFTDECA_OK);
  std::vector<float> per_vertex(user.vertices(), static_cast<float>(info.default_value));
  EXPECT_EQ(softdeca_avatar_set_parameter_vertices(a.p, 0, per_vertex.data(), static_cast<uint32_t>(per_vertex.size())),
            SOFTDECA_OK)
      << softdeca_last_error();
  std::vector<float> per_face(user.triangles.size() / 3, static_cast<float>(info.default_value));
  EXPECT_EQ(softdeca_avatar_set_parameter_faces(a.p, 0, per_face.data(), static_cast<uint32_t>(per_face.size())), SOFTDECA_OK)
      << softdeca_last_error();
  EXPECT_EQ(softdeca_avatar_set_parameter_vertices(a.p, 0, per_vertex.data(), 5), SOFTDECA_ERROR_INVALID_ARGUMENT);
  rt::Buffers out(user.vertices());
  std::vector<float> s(head_.vertices() * 3);
  EXPECT_EQ(softdeca_avatar_evaluate_surface(a.p, std::vector<float>(52, 0.f).data(), 52, s.data(),
                                             static_cast<uint32_t>(head_.vertices()), &out.out),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  rt::Buffers small(user.vertices() - 1);
  ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK);
  EXPECT_EQ(softdeca_avatar_evaluate_weights(a.p, std::vector<float>(52, 0.f).data(), 52, &small.out),
            SOFTDECA_ERROR_BUFFER_TOO_SMALL);
}

TEST_F(FitApi, BadMeshesGetClearErrors) {
  UserAvatar user(head_);
  FitPtr f;
  {
    UserAvatar nan = user;
    nan.neutral[7] = std::nanf("");
    nan.describe();
    EXPECT_EQ(fit(nan.mesh, f), SOFTDECA_ERROR_NON_FINITE);
    EXPECT_NE(std::string(softdeca_last_error()).find("non-finite"), std::string::npos) << softdeca_last_error();
  }
  {
    UserAvatar flat = user;
    std::fill(flat.deltas.begin(), flat.deltas.end(), 0.0f);
    flat.describe();
    EXPECT_EQ(fit(flat.mesh, f), SOFTDECA_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(std::string(softdeca_last_error()).find("moves a vertex"), std::string::npos) << softdeca_last_error();
  }
  {
    UserAvatar bad = user;
    bad.triangles[4] = static_cast<int32_t>(bad.vertices());
    bad.describe();
    EXPECT_EQ(fit(bad.mesh, f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  }
  softdeca_avatar_mesh m = user.mesh;
  m.blendshape_count = 51;
  EXPECT_EQ(fit(m, f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  m = user.mesh;
  m.struct_size = 8;
  EXPECT_EQ(fit(m, f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  m = user.mesh;
  m.vertex_count = 2;
  EXPECT_EQ(fit(m, f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(f.p, nullptr);
}

TEST_F(FitApi, StrayVerticesAndWildDeltasAreNamedNotMistakenForNoFace) {
  UserAvatar user(head_);
  FitPtr f;
  {
    UserAvatar far = user;
    far.neutral[3 * 5] = 1e30f;
    far.describe();
    EXPECT_EQ(fit(far.mesh, f), SOFTDECA_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(std::string(softdeca_last_error()).find("vertex 5 lies far outside the mesh"), std::string::npos) << softdeca_last_error();
  }
  {
    UserAvatar wild = user;
    int32_t jaw = -1;
    ASSERT_EQ(softdeca_blendshape_find_index("jawOpen", &jaw), SOFTDECA_OK);
    wild.deltas[3 * (static_cast<std::size_t>(jaw) * wild.vertices() + 9) + 1] = 3e38f;
    wild.describe();
    EXPECT_EQ(fit(wild.mesh, f), SOFTDECA_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(std::string(softdeca_last_error()).find("blendshape jawOpen moves vertex 9 by more than 2 times the mesh's size"),
              std::string::npos)
        << softdeca_last_error();
  }
  EXPECT_EQ(f.p, nullptr);
}

// Long thin triangles from the head's edges to random vertices of it, 100 for each of its own:
// fitted (the surface query cuts them into pieces near the template) or refused by name, never
// searched triangle by triangle (the work is bounded in tests/native/test_surface_query.cpp,
// the time measured by bench-reliability).
TEST_F(FitApi, AHeadWithTwentyThousandSliversFits) {
  UserAvatar user(head_);
  std::mt19937 random(5);
  const std::size_t head_triangles = head_.triangles.size() / 3;
  std::uniform_int_distribution<std::size_t> any_triangle(0, head_triangles - 1);
  std::uniform_int_distribution<std::int32_t> any_vertex(0, static_cast<std::int32_t>(head_.vertices()) - 1);
  for (int i = 0; i < 20000; ++i) {
    const std::int32_t* t = user.triangles.data() + 3 * any_triangle(random);
    user.triangles.insert(user.triangles.end(), {t[0], t[1], any_vertex(random)});
  }
  user.describe();
  FitPtr f;
  ASSERT_EQ(fit(user.mesh, f), SOFTDECA_OK) << softdeca_last_error();
}

TEST_F(FitApi, ChangedMeshesOtherBundlesAndDamagedFilesAreRefused) {
  UserAvatar user(head_);
  FitPtr f;
  ASSERT_EQ(fit(user.mesh, f), SOFTDECA_OK) << softdeca_last_error();
  // a changed mesh
  UserAvatar changed = user;
  changed.neutral[0] += 1.0f;
  changed.describe();
  rt::AvatarPtr a;
  EXPECT_EQ(rt::create_on_fit(model_.p, f.p, &changed.mesh, 1, 0, &a.p), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(std::string(softdeca_last_error()).find("fit it again"), std::string::npos) << softdeca_last_error();
  // another bundle
  rt::ModelPtr other;
  ASSERT_EQ(softdeca_model_load((rt::data_dir() + "/bundle_softdeca_only").c_str(), nullptr, &other.p), SOFTDECA_OK);
  const auto path = std::filesystem::temp_directory_path() / "softdeca-test-other.fit";
  ASSERT_EQ(softdeca_avatar_fit_save(f.p, path.string().c_str()), SOFTDECA_OK);
  FitPtr g;
  EXPECT_EQ(softdeca_avatar_fit_load(other.p, path.string().c_str(), &g.p), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(std::string(softdeca_last_error()).find("another bundle"), std::string::npos) << softdeca_last_error();
  // every truncation of the file is refused
  const std::vector<char> bytes = rt::read_bytes(path.string());
  for (std::size_t cut = 0; cut < bytes.size(); cut += std::max<std::size_t>(1, bytes.size() / 97)) {
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(cut));
    EXPECT_EQ(softdeca_avatar_fit_load(model_.p, path.string().c_str(), &g.p), SOFTDECA_ERROR_FORMAT) << cut;
  }
  std::filesystem::remove(path);
  // no template head: a clear error
  FitPtr none;
  EXPECT_EQ(softdeca_avatar_fit_create(other.p, &user.mesh, &options_, &none.p), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(softdeca_last_error()).find("template head"), std::string::npos) << softdeca_last_error();
}

TEST_F(FitApi, EveryBitFlippedInASavedFitIsRefused) {
  const auto path = folder("softdeca-test-flips") / "avatar.fit";
  FitPtr f;
  ASSERT_NO_FATAL_FAILURE(fit_and_save(f, path));
  const std::vector<char> bytes = rt::read_bytes(path.string());
  ASSERT_EQ(load(path), SOFTDECA_OK) << softdeca_last_error();
  // Every byte of the header and the first fields, then about 700 places spread over the rest.
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < softdeca::fit::kFitHeaderBytes + 200 && i < bytes.size(); ++i) at.push_back(i);
  for (std::size_t i = at.size(); i < bytes.size(); i += std::max<std::size_t>(1, bytes.size() / 700)) at.push_back(i);
  at.push_back(bytes.size() - 1);
  for (std::size_t k = 0; k < at.size(); ++k) {
    std::vector<char> damaged = bytes;
    damaged[at[k]] = static_cast<char>(damaged[at[k]] ^ (1 << (k % 8)));
    write_file(path, damaged);
    ASSERT_EQ(load(path), SOFTDECA_ERROR_FORMAT) << "bit " << k % 8 << " of byte " << at[k] << " flipped";
    const std::string e = softdeca_last_error();
    if (at[k] < 8) {
      EXPECT_NE(e.find("is not a SoftDECA fit file"), std::string::npos) << e;
    } else if (at[k] < 12) {
      EXPECT_NE(e.find("fit the avatar again"), std::string::npos) << e;
    } else {
      EXPECT_NE(e.find("avatar.fit is damaged (its checksum does not match); fit the avatar again"), std::string::npos) << e;
    }
  }
  // A fit file of the first version, without a checksum.
  std::vector<char> first = bytes;
  first[8] = 1;
  write_file(path, first);
  EXPECT_EQ(load(path), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(std::string(softdeca_last_error()).find("fit file version 1, without a checksum); fit the avatar again"), std::string::npos)
      << softdeca_last_error();
}

TEST_F(FitApi, ValuesNoFitHoldsAreRefusedUnderAMatchingChecksum) {
  namespace sf = softdeca::fit;
  UserAvatar user(head_);
  FitPtr f;
  ASSERT_EQ(fit(user.mesh, f), SOFTDECA_OK) << softdeca_last_error();
  const sf::AvatarFit& good = f.p->fit;
  ASSERT_GT(good.embedding.size(), 2u);
  const auto path = folder("softdeca-test-ranges") / "avatar.fit";
  const auto save = [&](const sf::AvatarFit& a) {
    const std::vector<std::uint8_t> b = sf::encode_fit(a, f.p->bundle_sha256, a.source.weight.size());
    write_file(path, std::vector<char>(b.begin(), b.end()));
  };
  save(good);
  ASSERT_EQ(load(path), SOFTDECA_OK) << "the fit as made: " << softdeca_last_error();

  struct Edit {
    const char* what;
    std::function<void(sf::AvatarFit&)> apply;
    const char* says;
  };
  const double unit = std::cbrt(std::fabs(good.placement.linear.determinant()));
  std::vector<Edit> edits = {
      {"an embedding offset of 1e30 m", [](sf::AvatarFit& a) { a.embedding.offset[1] = 1e30f; }, "an embedding offset lies 1e+30 m from the skin"},
      {"an embedding offset of 5 cm", [](sf::AvatarFit& a) { a.embedding.offset[0] = -0.05f; }, "beyond the fit's 10 mm"},
      {"an embedding weight of 1e30", [](sf::AvatarFit& a) { a.embedding.bary[3] = 1e30f; }, "barycentric weights"},
      {"embedding weights summing to 1.5", [](sf::AvatarFit& a) { a.embedding.bary[0] += 0.5f; }, "barycentric weights"},
      {"an embedded vertex listed twice", [](sf::AvatarFit& a) { a.embedding.vertex[1] = a.embedding.vertex[0]; }, "twice"},
      {"an embedding triangle out of range", [](sf::AvatarFit& a) { a.embedding.triangle[0] = -1; }, "not a skin triangle"},
      {"an embedding's own weight of 0", [](sf::AvatarFit& a) { a.embedding.weight[0] = 0; }, "outside (0, 1]"},
      {"a registered vertex at 1e30 m", [](sf::AvatarFit& a) { a.registered[4] = 1e30f; }, "a registered vertex lies"},
      {"a NaN in the registered head", [](sf::AvatarFit& a) { a.registered[0] = std::nanf(""); }, "non-finite"},
      {"a shape source's weight of 2", [](sf::AvatarFit& a) { a.source.weight[0] = 2; }, "weight is outside [0, 1]"},
      {"a shape source's barycentric weight of -3", [](sf::AvatarFit& a) { a.source.bary[0] = -3; a.source.weight[0] = 1; },
       "barycentric weights"},
      {"a shape source outside the avatar", [](sf::AvatarFit& a) { a.source.corners[2] = static_cast<std::int32_t>(a.vertex_count); },
       "not a vertex of the avatar"},
      {"a unit of 1e-300 m", [&](sf::AvatarFit& a) { a.placement.linear *= 1e-300 / unit; }, "its unit is"},
      {"a unit of 1e4 m", [&](sf::AvatarFit& a) { a.placement.linear *= 1e4 / unit; }, "its unit is 1e+04 m, outside 1e-06 to 1000 m"},
      {"a sheared placement", [&](sf::AvatarFit& a) { a.placement.linear(0, 1) += 0.5 * unit; }, "not a turn and a scale"},
      {"the avatar placed 1e30 m away", [](sf::AvatarFit& a) { a.placement.offset[2] = 1e30; }, "moves the avatar"},
      {"a mesh hash that is not one", [](sf::AvatarFit& a) { a.mesh_sha256[5] = 'Z'; }, "SHA-256"},
  };
  if (!good.identity.empty())
    edits.push_back({"an identity coefficient of 1e30", [](sf::AvatarFit& a) { a.identity[0] = 1e30f; }, "an identity coefficient is"});
  for (const Edit& e : edits) {
    sf::AvatarFit bad = good;
    e.apply(bad);
    save(bad);
    EXPECT_EQ(load(path), SOFTDECA_ERROR_FORMAT) << e.what;
    const std::string error = softdeca_last_error();
    EXPECT_NE(error.find("avatar.fit is damaged ("), std::string::npos) << e.what << ": " << error;
    EXPECT_NE(error.find(e.says), std::string::npos) << e.what << ": " << error;
    EXPECT_NE(error.find("fit the avatar again"), std::string::npos) << e.what << ": " << error;
  }
}

TEST_F(FitApi, AUnitOutsideTheRangeAFitLoadsInIsRefused) {
  UserAvatar user(head_);
  for (const double unit : {1e-300, 1e-7, 1001.0, -0.01, static_cast<double>(std::nanf(""))}) {
    options_.metres_per_unit = unit;
    FitPtr f;
    EXPECT_EQ(fit(user.mesh, f), SOFTDECA_ERROR_INVALID_ARGUMENT) << unit;
    EXPECT_NE(std::string(softdeca_last_error()).find("1e-06 to 1000 m"), std::string::npos) << softdeca_last_error();
  }
}

TEST_F(FitApi, ThreadsSavingToOnePathAlwaysLeaveAFitThatLoads) {
  const auto dir = folder("softdeca-test-fit-threads");
  const auto path = dir / "shared.fit";
  FitPtr f;
  ASSERT_NO_FATAL_FAILURE(fit_and_save(f, path));
  std::atomic<bool> done{false};
  std::atomic<int> loads{0}, refused{0}, failed_saves{0};
  std::thread reader([&] {
    while (!done) {
      ++loads;
      if (load(path) != SOFTDECA_OK) ++refused;
    }
  });
  std::vector<std::thread> savers;
  for (int t = 0; t < 8; ++t)
    savers.emplace_back([&] {
      for (int round = 0; round < 30; ++round)
        if (softdeca_avatar_fit_save(f.p, path.string().c_str()) != SOFTDECA_OK) ++failed_saves;
    });
  for (std::thread& t : savers) t.join();
  done = true;
  reader.join();
  EXPECT_EQ(failed_saves, 0);
  EXPECT_EQ(refused, 0) << "of " << loads << " loads during the saves";
  EXPECT_EQ(load(path), SOFTDECA_OK) << softdeca_last_error();
  EXPECT_EQ(entries(dir), std::vector<std::string>{"shared.fit"}) << "no temporary file is left";
}

TEST_F(FitApi, AFailedSaveLeavesThePreviousFitAndNoTemporaryFile) {
  const auto dir = folder("softdeca-test-fit-fail");
  const auto kept = dir / "kept.fit";
  FitPtr f;
  ASSERT_NO_FATAL_FAILURE(fit_and_save(f, kept));
  const std::vector<char> before = rt::read_bytes(kept.string());
  std::filesystem::create_directories(dir / "a folder" / "inside");
  for (const auto& bad : {kept / "below a file.fit", dir / "a folder", dir / "missing" / "x.fit"}) {
    EXPECT_EQ(softdeca_avatar_fit_save(f.p, bad.string().c_str()), SOFTDECA_ERROR_IO) << bad;
    EXPECT_NE(std::string(softdeca_last_error()).find("could not save " + bad.string()), std::string::npos) << softdeca_last_error();
  }
  EXPECT_EQ(rt::read_bytes(kept.string()), before);
  EXPECT_EQ(load(kept), SOFTDECA_OK) << softdeca_last_error();
  EXPECT_EQ(entries(dir), (std::vector<std::string>{"a folder", "kept.fit"})) << "no temporary file is left";
  EXPECT_EQ(entries(dir / "a folder"), std::vector<std::string>{"inside"});
}

}  // namespace
