// Fitting a user's avatar through the C ABI on the runtime tests' synthetic bundle: the head
// shuffled, in centimetres and inside a body is fitted, saved, loaded and animated; what the
// embedding does not hold moves exactly as the rig; hostile meshes and fit files get errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>

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
    softdeca_avatar_fit_report(f.p, nullptr, 0, &length);
    std::string text(length + 1, '\0');
    EXPECT_EQ(softdeca_avatar_fit_report(f.p, text.data(), length + 1, &length), SOFTDECA_OK);
    text.resize(length);
    return text;
  }
  rt::Head head_;
  rt::ModelPtr model_;
  softdeca_fit_options options_{};
};

TEST_F(FitApi, FitsSavesLoadsAndAnimatesTheUsersOwnMesh) {
  UserAvatar user(head_);
  FitPtr f;
  ASSERT_EQ(fit(user.mesh, f), SOFTDECA_OK) << softdeca_last_error();
  const std::string r = report(f);
  EXPECT_NE(r.find("\"metres_per_unit\": 0.01"), std::string::npos) << r;
  EXPECT_NE(r.find("\"face_residual_mm_mean\""), std::string::npos) << r;

  const auto path = std::filesystem::temp_directory_path() / "softdeca-test.fit";
  ASSERT_EQ(softdeca_avatar_fit_save(f.p, path.string().c_str()), SOFTDECA_OK) << softdeca_last_error();
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".part"));
  FitPtr loaded;
  ASSERT_EQ(softdeca_avatar_fit_load(model_.p, path.string().c_str(), &loaded.p), SOFTDECA_OK) << softdeca_last_error();
  EXPECT_EQ(report(loaded), r);

  rt::AvatarPtr a;
  ASSERT_EQ(softdeca_avatar_create_fitted(model_.p, loaded.p, &user.mesh, 1, SOFTDECA_PRECISION_HALF, &a.p), SOFTDECA_OK)
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

TEST_F(FitApi, AFittedAvatarTakesMapsPerAvatarElement) {
  UserAvatar user(head_);
  FitPtr f;
  ASSERT_EQ(fit(user.mesh, f), SOFTDECA_OK) << softdeca_last_error();
  rt::AvatarPtr a;
  ASSERT_EQ(softdeca_avatar_create_fitted(model_.p, f.p, &user.mesh, 1, SOFTDECA_PRECISION_FLOAT, &a.p), SOFTDECA_OK);
  softdeca_parameter_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(softdeca_model_get_parameter(model_.p, 0, &info), SOFTDECA_OK);
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
    ASSERT_EQ(softdeca_blendshape_index("jawOpen", &jaw), SOFTDECA_OK);
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
  EXPECT_EQ(softdeca_avatar_create_fitted(model_.p, f.p, &changed.mesh, 1, 0, &a.p), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(std::string(softdeca_last_error()).find("fit it again"), std::string::npos) << softdeca_last_error();
  // another bundle
  rt::ModelPtr other;
  ASSERT_EQ(softdeca_model_load((rt::data_dir() + "/bundle_softdeca_only").c_str(), nullptr, &other.p), SOFTDECA_OK);
  const auto path = std::filesystem::temp_directory_path() / "softdeca-test-other.fit";
  ASSERT_EQ(softdeca_avatar_fit_save(f.p, path.string().c_str()), SOFTDECA_OK);
  FitPtr g;
  EXPECT_EQ(softdeca_avatar_fit_load(other.p, path.string().c_str(), &g.p), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(std::string(softdeca_last_error()).find("another bundle"), std::string::npos) << softdeca_last_error();
  // every truncation of the file, and flipped bytes, are refused or load whole: never a crash
  const std::vector<char> bytes = rt::read_bytes(path.string());
  for (std::size_t cut = 0; cut < bytes.size(); cut += std::max<std::size_t>(1, bytes.size() / 97)) {
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(cut));
    EXPECT_EQ(softdeca_avatar_fit_load(model_.p, path.string().c_str(), &g.p), SOFTDECA_ERROR_FORMAT) << cut;
  }
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<char> damaged = bytes;
    damaged[rng() % damaged.size()] ^= static_cast<char>(1 + rng() % 255);
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(damaged.data(), static_cast<std::streamsize>(damaged.size()));
    FitPtr h;
    const softdeca_status s = softdeca_avatar_fit_load(model_.p, path.string().c_str(), &h.p);
    EXPECT_TRUE(s == SOFTDECA_OK || s == SOFTDECA_ERROR_FORMAT) << softdeca_status_name(s);
  }
  std::filesystem::remove(path);
  // no template head: a clear error
  FitPtr none;
  EXPECT_EQ(softdeca_avatar_fit_create(other.p, &user.mesh, &options_, &none.p), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(softdeca_last_error()).find("template head"), std::string::npos) << softdeca_last_error();
}

}  // namespace
