// The runtime's C ABI with good and hostile input: every function with null pointers, short
// buffers, wrong sizes, NaN, mismatched bundle versions and damaged files gets a clear status
// and message, never a crash, and leaves its outputs untouched.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "runtime_fixture.h"

namespace {
using namespace rt;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::string error() { return softdeca_last_error(); }

class Runtime : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_TEST_DATA();
    head = Head::load();
    ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle").c_str(), nullptr, &model.p), SOFTDECA_OK) << error();
    info.struct_size = sizeof info;
    ASSERT_EQ(softdeca_model_get_info(model.p, &info), SOFTDECA_OK);
    const auto d = describe(head);
    ASSERT_EQ(softdeca_avatar_create(model.p, &d, &avatar.p), SOFTDECA_OK) << error();
    weights.assign(52, 0.0f);
    weights[24] = 0.7f;  // jawOpen
    weights[3] = 0.4f;
  }
  Head head;
  ModelPtr model;
  AvatarPtr avatar;
  softdeca_model_info info{};
  std::vector<float> weights;
};

TEST_F(Runtime, ModelInfoDescribesTheBundle) {
  EXPECT_EQ(info.format_version, 5u);  // with the template head: written as version 5
  EXPECT_LE(info.format_version, static_cast<uint32_t>(SOFTDECA_BUNDLE_FORMAT_VERSION));
  EXPECT_EQ(info.head_vertex_count, head.vertices());
  EXPECT_EQ(info.blendshape_count, 52u);
  EXPECT_EQ(info.has_softdeca, 1u);
  EXPECT_EQ(info.has_sparse, 1u);
  EXPECT_EQ(info.untrained, 1u);
  EXPECT_GT(info.landmark_count, 0u);
  softdeca_parameter_info p{};
  p.struct_size = sizeof p;
  uint32_t index = 99;
  ASSERT_EQ(softdeca_model_find_parameter(model.p, "w_skin_strain", &index), SOFTDECA_OK);
  ASSERT_EQ(softdeca_model_get_parameter_info(model.p, index, &p), SOFTDECA_OK);
  EXPECT_STREQ(p.name, "w_skin_strain");
  EXPECT_EQ(p.log_scale, 1);
  EXPECT_STREQ(p.domain, "skin_triangle");
  EXPECT_DOUBLE_EQ(p.minimum, 0.001);
  EXPECT_DOUBLE_EQ(p.maximum, 100.0);
  uint32_t gravity = 0;
  ASSERT_EQ(softdeca_model_find_parameter(model.p, "gravity_strength", &gravity), SOFTDECA_OK);
  ASSERT_EQ(softdeca_model_get_parameter_info(model.p, gravity, &p), SOFTDECA_OK);
  EXPECT_STREQ(p.domain, "global");
  p.struct_size = 4;
  EXPECT_EQ(softdeca_model_get_parameter_info(model.p, gravity, &p), SOFTDECA_ERROR_INVALID_ARGUMENT);
  p.struct_size = sizeof p;
  EXPECT_EQ(softdeca_model_find_parameter(model.p, "no_such", &index), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("no_such"), std::string::npos);
  EXPECT_EQ(softdeca_model_get_parameter_info(model.p, info.parameter_count, &p), SOFTDECA_ERROR_INVALID_ARGUMENT);
}

TEST_F(Runtime, ModelQueriesCheckTheirArguments) {
  softdeca_model_info small{};
  small.struct_size = sizeof small - 4;
  EXPECT_EQ(softdeca_model_get_info(model.p, &small), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("size"), std::string::npos);
  EXPECT_EQ(softdeca_model_get_info(nullptr, &info), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("model is null"), std::string::npos);
  EXPECT_EQ(softdeca_model_get_info(model.p, nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
  std::vector<int32_t> lm(info.landmark_count);
  EXPECT_EQ(softdeca_model_get_landmark_vertices(model.p, lm.data(), lm.size() - 1), SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  EXPECT_EQ(softdeca_model_get_landmark_vertices(model.p, nullptr, lm.size()), SOFTDECA_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(softdeca_model_get_landmark_vertices(model.p, lm.data(), lm.size()), SOFTDECA_OK);
  for (const int32_t v : lm) EXPECT_LT(static_cast<uint32_t>(v), info.arkit_vertex_count);
  std::vector<int32_t> tri(3 * info.skin_triangle_count);
  EXPECT_EQ(softdeca_model_get_skin_triangles(model.p, tri.data(), info.skin_triangle_count - 1), SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  ASSERT_EQ(softdeca_model_get_skin_triangles(model.p, tri.data(), info.skin_triangle_count), SOFTDECA_OK);
  std::vector<float> points(3 * info.landmark_count);
  EXPECT_EQ(softdeca_model_evaluate_landmarks(model.p, head.neutral.data(), 7, points.data(), info.landmark_count),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  auto bad = head.neutral;
  bad[5] = kNaN;
  EXPECT_EQ(softdeca_model_evaluate_landmarks(model.p, bad.data(), head.vertices(), points.data(), info.landmark_count),
            SOFTDECA_ERROR_NON_FINITE);
  ASSERT_EQ(softdeca_model_evaluate_landmarks(model.p, head.neutral.data(), head.vertices(), points.data(), info.landmark_count),
            SOFTDECA_OK);
  EXPECT_EQ(softdeca_model_find_parameter(model.p, nullptr, nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
}

TEST_F(Runtime, LoadingRejectsBadPathsAndArguments) {
  softdeca_model* m = nullptr;
  EXPECT_EQ(softdeca_model_load("/nonexistent/bundle", nullptr, &m), SOFTDECA_ERROR_IO);
  EXPECT_NE(error().find("/nonexistent/bundle"), std::string::npos);
  EXPECT_EQ(m, nullptr);
  EXPECT_EQ(softdeca_model_load(nullptr, nullptr, &m), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_model_load((data_dir() + "/bundle").c_str(), nullptr, nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
  softdeca_model_options opts{sizeof(softdeca_model_options) - 1, 1, 0};
  EXPECT_EQ(softdeca_model_load((data_dir() + "/bundle").c_str(), &opts, &m), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_model_load_memory(nullptr, 10, nullptr, &m), SOFTDECA_ERROR_INVALID_ARGUMENT);
  const char junk[3] = {1, 2, 3};
  EXPECT_EQ(softdeca_model_load_memory(junk, 0, nullptr, &m), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_model_load_memory(junk, sizeof junk, nullptr, &m), SOFTDECA_ERROR_FORMAT);
  EXPECT_EQ(m, nullptr);
  softdeca_model_destroy(nullptr);  // destroy functions accept NULL
  softdeca_avatar_destroy(nullptr);
}

TEST_F(Runtime, LoadsFromMemoryAndFromATarFile) {
  const auto tar = read_bytes(data_dir() + "/bundle.tar");
  ASSERT_FALSE(tar.empty());
  ModelPtr m;
  ASSERT_EQ(softdeca_model_load_memory(tar.data(), static_cast<uint32_t>(tar.size()), nullptr, &m.p), SOFTDECA_OK) << error();
  ModelPtr f;
  ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle.tar").c_str(), nullptr, &f.p), SOFTDECA_OK) << error();
  // Damaged archives: a truncated one and one with a broken header checksum.
  EXPECT_EQ(softdeca_model_load_memory(tar.data(), static_cast<uint32_t>(tar.size() / 3), nullptr, &m.p), SOFTDECA_ERROR_FORMAT);
  EXPECT_FALSE(error().empty());
  auto broken = tar;
  broken[10] ^= 0x5A;
  softdeca_model* x = nullptr;
  EXPECT_EQ(softdeca_model_load_memory(broken.data(), static_cast<uint32_t>(broken.size()), nullptr, &x), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(error().find("checksum"), std::string::npos) << error();
}

TEST_F(Runtime, RefusesAnotherFormatVersion) {
  const std::string newest = std::to_string(SOFTDECA_BUNDLE_FORMAT_VERSION);
  const std::string next = std::to_string(SOFTDECA_BUNDLE_FORMAT_VERSION + 1);
  BundleCopy copy(data_dir() + "/bundle", "version");
  copy.replace_in("manifest.json", "\"format_version\": 5", "\"format_version\": " + next);
  softdeca_model* m = nullptr;
  EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(error().find("version " + next), std::string::npos) << error();
  EXPECT_NE(error().find("versions 1 to " + newest), std::string::npos) << error();
  EXPECT_EQ(m, nullptr);
}

TEST_F(Runtime, TheVertexStageNeedsVersionTwoAndTheSoftDecaModel) {
  // softdeca.f_ph_v under a version-1 manifest: refused (a version-1 reader would ignore it)
  BundleCopy copy(data_dir() + "/bundle", "stage");
  copy.replace_in("manifest.json", "\"sparse.f_ph_v\"", "\"softdeca.f_ph_v\"");
  copy.replace_in("manifest.json", "\"format_version\": 5", "\"format_version\": 1");
  softdeca_model* m = nullptr;
  EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(error().find("format version 2"), std::string::npos) << error();
  // under version 2 the sparse model now lacks its f_ph_v
  copy.replace_in("manifest.json", "\"format_version\": 1", "\"format_version\": 2");
  EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(error().find("sparse.f_ph_v"), std::string::npos) << error();
  EXPECT_EQ(m, nullptr);
}

TEST_F(Runtime, RefusesSizesThatDisagree) {
  {
    BundleCopy copy(data_dir() + "/bundle", "sizes");
    copy.replace_in("manifest.json", "\"skin_triangles\": " + std::to_string(info.skin_triangle_count),
                    "\"skin_triangles\": " + std::to_string(info.skin_triangle_count + 1));
    softdeca_model* m = nullptr;
    EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
    EXPECT_FALSE(error().empty());
  }
  {
    BundleCopy copy(data_dir() + "/bundle", "tri");
    copy.write("skin_triangles.i32", std::string(12, '\0'));
    softdeca_model* m = nullptr;
    EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
    EXPECT_NE(error().find("skin_triangles.i32"), std::string::npos) << error();
  }
  {
    BundleCopy copy(data_dir() + "/bundle", "latent");
    copy.replace_in("manifest.json", "\"latent_size\": 32", "\"latent_size\": 31");
    softdeca_model* m = nullptr;
    EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
    EXPECT_NE(error().find("shape"), std::string::npos) << error();
  }
  {
    BundleCopy copy(data_dir() + "/bundle", "format");
    copy.replace_in("manifest.json", "\"softdeca-bundle\"", "\"something-else\"");
    softdeca_model* m = nullptr;
    EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
    EXPECT_NE(error().find("not a SoftDECA model bundle"), std::string::npos) << error();
  }
  {
    BundleCopy copy(data_dir() + "/bundle", "json");
    copy.write("manifest.json", "{\"format\": \"softdeca-bundle\", ");
    softdeca_model* m = nullptr;
    EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
    EXPECT_NE(error().find("JSON"), std::string::npos) << error();
  }
}

TEST_F(Runtime, RefusesCorruptOnnxBytes) {
  for (const char* file : {"softdeca_f_ph.onnx", "sparse_f_l.onnx", "identity_encoder.onnx"}) {
    BundleCopy copy(data_dir() + "/bundle", "onnx");
    auto bytes = read_bytes(copy.file(file));
    ASSERT_GT(bytes.size(), 64u);
    for (std::size_t i = 16; i < bytes.size(); i += 7) bytes[i] = static_cast<char>(bytes[i] ^ 0xA5);
    copy.write(file, std::string(bytes.begin(), bytes.end()));
    softdeca_model* m = nullptr;
    EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT) << file;
    EXPECT_NE(error().find(file), std::string::npos) << error();
    EXPECT_EQ(m, nullptr);
  }
  BundleCopy copy(data_dir() + "/bundle", "swap");  // a valid ONNX file with the wrong interface
  std::filesystem::copy_file(copy.file("softdeca_f_w.onnx"), copy.file("softdeca_f_ph.onnx"),
                             std::filesystem::copy_options::overwrite_existing);
  softdeca_model* m = nullptr;
  EXPECT_EQ(softdeca_model_load(copy.path().c_str(), nullptr, &m), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(error().find("softdeca_f_ph.onnx"), std::string::npos) << error();
}

TEST_F(Runtime, AvatarCreationChecksTheMesh) {
  softdeca_avatar* a = nullptr;
  auto d = describe(head);
  EXPECT_EQ(softdeca_avatar_create(nullptr, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_create(model.p, nullptr, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
  d.struct_size = 8;
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  d = describe(head);
  d.m.vertex_count -= 1;
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("head vertices"), std::string::npos) << error();
  d = describe(head);
  d.m.neutral = nullptr;
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  d = describe(head);
  d.mesh = nullptr;
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("desc->mesh"), std::string::npos) << error();
  d = describe(head);
  d.m.struct_size = 8;
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  auto nan_head = head;
  nan_head.neutral[7] = kNaN;
  d = describe(nan_head);
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_NON_FINITE);
  EXPECT_NE(error().find("neutral[7]"), std::string::npos) << error();
  auto bad_tri = head;
  bad_tri.triangles[4] = static_cast<int32_t>(head.vertices());
  d = describe(bad_tri);
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  d = describe(head);
  d.m.blendshape_count = 51;
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  auto nan_shapes = head;
  nan_shapes.blendshapes[100] = std::numeric_limits<float>::infinity();
  d = describe(nan_shapes);
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_NON_FINITE);
  d = describe(head);
  d.threads = 99;
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  d = describe(head);
  d.precision = 7;
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  // A skin triangle collapsed to a point: deformation transfer is undefined there.
  auto flat = head;
  std::vector<int32_t> tri(3 * info.skin_triangle_count);
  ASSERT_EQ(softdeca_model_get_skin_triangles(model.p, tri.data(), info.skin_triangle_count), SOFTDECA_OK);
  for (int k = 1; k < 3; ++k)
    for (int c = 0; c < 3; ++c) flat.neutral[3 * tri[k] + c] = flat.neutral[3 * tri[0] + c];
  d = describe(flat);
  EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("degenerate"), std::string::npos) << error();
  EXPECT_EQ(a, nullptr);
}

TEST_F(Runtime, FramesNeedAPreparation) {
  Buffers b(head.vertices());
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &b.out), SOFTDECA_ERROR_NOT_READY);
  EXPECT_NE(error().find("prepare"), std::string::npos);
  const auto pts = head.user_face(weights.data());
  EXPECT_EQ(softdeca_avatar_evaluate_landmarks(avatar.p, pts.data(), head.user_vertices(), &b.out), SOFTDECA_ERROR_NOT_READY);
  // Linear blendshapes need none.
  EXPECT_EQ(softdeca_avatar_evaluate_linear(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
}

TEST_F(Runtime, BadFramesLeaveTheLastOutputUntouched) {
  ASSERT_EQ(softdeca_avatar_prepare(avatar.p), SOFTDECA_OK) << error();
  Buffers b(head.vertices());
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK) << error();
  const auto good_v = b.vertices, good_n = b.normals;
  auto expect_untouched = [&](const char* what) {
    EXPECT_EQ(b.vertices, good_v) << what;
    EXPECT_EQ(b.normals, good_n) << what;
  };
  auto w = weights;
  w[10] = kNaN;
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, w.data(), 52, &b.out), SOFTDECA_ERROR_NON_FINITE);
  EXPECT_NE(error().find("weights[10]"), std::string::npos) << error();
  expect_untouched("NaN weight");
  w = weights;
  w[2] = 1.5f;
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, w.data(), 52, &b.out), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("browInnerUp"), std::string::npos) << error();
  expect_untouched("weight out of range");
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 51, &b.out), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, nullptr, 52, &b.out), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_evaluate_weights(nullptr, weights.data(), 52, &b.out), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
  softdeca_output small = b.out;
  small.vertex_capacity -= 1;
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &small), SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  small = b.out;
  small.normal_capacity = 3;
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &small), SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  small = b.out;
  small.struct_size = 4;
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &small), SOFTDECA_ERROR_INVALID_ARGUMENT);
  small = b.out;
  small.vertices = nullptr;
  EXPECT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &small), SOFTDECA_ERROR_INVALID_ARGUMENT);
  expect_untouched("bad output");
  // Surfaces: wrong size, NaN.
  std::vector<float> surface(head.neutral);
  EXPECT_EQ(softdeca_avatar_evaluate_surface(avatar.p, weights.data(), 52, surface.data(), 10, &b.out),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  surface[30] = kNaN;
  EXPECT_EQ(softdeca_avatar_evaluate_surface(avatar.p, weights.data(), 52, surface.data(), head.vertices(), &b.out),
            SOFTDECA_ERROR_NON_FINITE);
  EXPECT_EQ(softdeca_avatar_evaluate_surface(avatar.p, weights.data(), 52, nullptr, head.vertices(), &b.out),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  expect_untouched("bad surface");
  // Landmarks: wrong count, NaN, null.
  auto pts = head.user_face(weights.data());
  EXPECT_EQ(softdeca_avatar_evaluate_landmarks(avatar.p, pts.data(), 5, &b.out), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("landmarks"), std::string::npos) << error();
  pts[1] = kNaN;
  EXPECT_EQ(softdeca_avatar_evaluate_landmarks(avatar.p, pts.data(), head.user_vertices(), &b.out), SOFTDECA_ERROR_NON_FINITE);
  EXPECT_EQ(softdeca_avatar_calibrate_landmarks(avatar.p, pts.data(), head.user_vertices()), SOFTDECA_ERROR_NON_FINITE);
  EXPECT_EQ(softdeca_avatar_calibrate_landmarks(avatar.p, nullptr, head.user_vertices()), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_evaluate_landmarks(avatar.p, nullptr, head.user_vertices(), &b.out), SOFTDECA_ERROR_INVALID_ARGUMENT);
  std::vector<float> same(3 * info.landmark_count, 0.25f);  // every landmark in one point
  EXPECT_EQ(softdeca_avatar_calibrate_landmarks(avatar.p, same.data(), info.landmark_count), SOFTDECA_ERROR_INVALID_ARGUMENT);
  expect_untouched("bad landmarks");
  EXPECT_EQ(softdeca_avatar_evaluate_linear(avatar.p, weights.data(), 3, &b.out), SOFTDECA_ERROR_INVALID_ARGUMENT);
  expect_untouched("bad linear");
  // The next good frame reproduces the first (static, same preparation).
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  expect_untouched("same frame again");
}

TEST_F(Runtime, ParametersAreCheckedAndLocalised) {
  uint32_t strain = 0, gravity = 0;
  ASSERT_EQ(softdeca_model_find_parameter(model.p, "w_skin_strain", &strain), SOFTDECA_OK);
  ASSERT_EQ(softdeca_model_find_parameter(model.p, "gravity_strength", &gravity), SOFTDECA_OK);
  EXPECT_EQ(softdeca_avatar_set_parameter(avatar.p, strain, 1000.0f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("outside"), std::string::npos) << error();
  EXPECT_EQ(softdeca_avatar_set_parameter(avatar.p, strain, kNaN), SOFTDECA_ERROR_NON_FINITE);
  EXPECT_EQ(softdeca_avatar_set_parameter(avatar.p, 999, 1.0f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_set_parameter(nullptr, strain, 1.0f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  std::vector<float> faces(info.skin_triangle_count, 50.0f), vertices(info.skin_vertex_count, 50.0f);
  EXPECT_EQ(softdeca_avatar_set_parameter_faces(avatar.p, strain, faces.data(), faces.size() - 1), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_set_parameter_faces(avatar.p, strain, nullptr, faces.size()), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_set_parameter_faces(avatar.p, gravity, faces.data(), faces.size()), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("global"), std::string::npos) << error();
  faces[3] = kNaN;
  EXPECT_EQ(softdeca_avatar_set_parameter_faces(avatar.p, strain, faces.data(), faces.size()), SOFTDECA_ERROR_NON_FINITE);
  faces[3] = 1e6f;
  EXPECT_EQ(softdeca_avatar_set_parameter_faces(avatar.p, strain, faces.data(), faces.size()), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_set_parameter_vertices(avatar.p, strain, vertices.data(), 3), SOFTDECA_ERROR_INVALID_ARGUMENT);
  double value = 0;
  softdeca_bool localised = 7;
  ASSERT_EQ(softdeca_avatar_get_parameter(avatar.p, strain, &value, &localised), SOFTDECA_OK);
  EXPECT_DOUBLE_EQ(value, 1.0);  // the default, untouched by the rejected calls
  EXPECT_EQ(localised, SOFTDECA_FALSE);
  // A regional change moves the output; resetting brings the default output back.
  ASSERT_EQ(softdeca_avatar_prepare(avatar.p), SOFTDECA_OK);
  Buffers base(head.vertices()), changed(head.vertices()), back(head.vertices());
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &base.out), SOFTDECA_OK);
  faces.assign(info.skin_triangle_count, 1.0f);
  for (std::size_t f = 0; f < faces.size() / 4; ++f) faces[f] = 80.0f;
  ASSERT_EQ(softdeca_avatar_set_parameter_faces(avatar.p, strain, faces.data(), faces.size()), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_get_parameter(avatar.p, strain, nullptr, &localised), SOFTDECA_OK);
  EXPECT_EQ(localised, SOFTDECA_TRUE);
  ASSERT_EQ(softdeca_avatar_prepare(avatar.p), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &changed.out), SOFTDECA_OK);
  EXPECT_NE(base.vertices, changed.vertices);
  ASSERT_EQ(softdeca_avatar_reset_parameters(avatar.p), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_prepare(avatar.p), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &back.out), SOFTDECA_OK);
  EXPECT_EQ(base.vertices, back.vertices);
}

TEST_F(Runtime, IdentityCanBeReadAndSet) {
  std::vector<float> h(info.identity_size);
  EXPECT_EQ(softdeca_avatar_get_identity(avatar.p, h.data(), h.size() - 1), SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  EXPECT_EQ(softdeca_avatar_get_identity(avatar.p, nullptr, h.size()), SOFTDECA_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(softdeca_avatar_get_identity(avatar.p, h.data(), h.size()), SOFTDECA_OK);
  EXPECT_TRUE(std::any_of(h.begin(), h.end(), [](float x) { return x != 0.0f; }));
  EXPECT_EQ(softdeca_avatar_set_identity(avatar.p, h.data(), h.size() + 1), SOFTDECA_ERROR_INVALID_ARGUMENT);
  auto bad = h;
  bad[0] = kNaN;
  EXPECT_EQ(softdeca_avatar_set_identity(avatar.p, bad.data(), bad.size()), SOFTDECA_ERROR_NON_FINITE);
  std::vector<float> zero(h.size(), 0.0f);
  ASSERT_EQ(softdeca_avatar_set_identity(avatar.p, zero.data(), zero.size()), SOFTDECA_OK);
  std::vector<float> back(h.size(), 1.0f);
  ASSERT_EQ(softdeca_avatar_get_identity(avatar.p, back.data(), back.size()), SOFTDECA_OK);
  EXPECT_EQ(back, zero);
}

TEST_F(Runtime, StatsAndDynamicsControls) {
  softdeca_stats s{};
  s.struct_size = sizeof s - 8;
  EXPECT_EQ(softdeca_avatar_get_stats(avatar.p, &s), SOFTDECA_ERROR_INVALID_ARGUMENT);
  s.struct_size = sizeof s;
  EXPECT_EQ(softdeca_avatar_get_stats(nullptr, &s), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_set_dynamics(nullptr, SOFTDECA_TRUE), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_reset_dynamics(nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_prepare(nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(softdeca_avatar_prepare(avatar.p), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_set_dynamics(avatar.p, SOFTDECA_TRUE), SOFTDECA_OK);
  Buffers b(head.vertices());
  for (int i = 0; i < 3; ++i) ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_get_stats(avatar.p, &s), SOFTDECA_OK);
  EXPECT_EQ(s.frames, 3u);
  EXPECT_EQ(s.preparations, 1u);
  EXPECT_EQ(s.generation, 1u);
  EXPECT_GT(s.frame_ms, 0.0);
  EXPECT_GT(s.prepare_ms, 0.0);
  EXPECT_GT(s.factorisation_ms, 0.0);
  EXPECT_GT(s.memory_bytes, 0u);
  EXPECT_EQ(s.threads, 1u);
}

TEST_F(Runtime, DynamicsKeepAConstantInputConstant) {
  ASSERT_EQ(softdeca_avatar_prepare(avatar.p), SOFTDECA_OK);
  Buffers still(head.vertices()), moving(head.vertices());
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &still.out), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_set_dynamics(avatar.p, SOFTDECA_TRUE), SOFTDECA_OK);
  for (int i = 0; i < 20; ++i) {
    ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &moving.out), SOFTDECA_OK);
    for (std::size_t k = 0; k < still.vertices.size(); ++k) ASSERT_NEAR(moving.vertices[k], still.vertices[k], 1e-6) << i;
  }
  // A step in the input lags behind with dynamics and settles on the static output.
  std::vector<float> w2(52, 0.0f);
  Buffers target(head.vertices());
  ASSERT_EQ(softdeca_avatar_set_dynamics(avatar.p, SOFTDECA_FALSE), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, w2.data(), 52, &target.out), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_set_dynamics(avatar.p, SOFTDECA_TRUE), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &moving.out), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, w2.data(), 52, &moving.out), SOFTDECA_OK);
  double lag = 0;
  for (std::size_t k = 0; k < target.vertices.size(); ++k) lag = std::max(lag, double(std::fabs(moving.vertices[k] - target.vertices[k])));
  EXPECT_GT(lag, 1e-5);
  for (int i = 0; i < 400; ++i) ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, w2.data(), 52, &moving.out), SOFTDECA_OK);
  for (std::size_t k = 0; k < target.vertices.size(); ++k) ASSERT_NEAR(moving.vertices[k], target.vertices[k], 1e-6);
}

TEST_F(Runtime, SoftDecaOnlyBundleRefusesLandmarks) {
  ModelPtr only;
  ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle_softdeca_only").c_str(), nullptr, &only.p), SOFTDECA_OK) << error();
  AvatarPtr a;
  const auto d = describe(head);
  ASSERT_EQ(softdeca_avatar_create(only.p, &d, &a.p), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK);
  Buffers b(head.vertices());
  const auto pts = head.user_face(weights.data());
  EXPECT_EQ(softdeca_avatar_evaluate_landmarks(a.p, pts.data(), head.user_vertices(), &b.out), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("no SparseSoftDECA"), std::string::npos) << error();
  EXPECT_EQ(softdeca_avatar_evaluate_weights(a.p, weights.data(), 52, &b.out), SOFTDECA_OK);
}

TEST_F(Runtime, AvatarsOutliveTheirModel) {
  ModelPtr m;
  ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle").c_str(), nullptr, &m.p), SOFTDECA_OK);
  AvatarPtr a;
  const auto d = describe(head);
  ASSERT_EQ(softdeca_avatar_create(m.p, &d, &a.p), SOFTDECA_OK);
  softdeca_model_destroy(m.p);
  m.p = nullptr;
  ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK) << error();
  Buffers b(head.vertices());
  EXPECT_EQ(softdeca_avatar_evaluate_weights(a.p, weights.data(), 52, &b.out), SOFTDECA_OK) << error();
}

TEST_F(Runtime, LastErrorIsPerThreadAndClearedBySuccess) {
  EXPECT_EQ(softdeca_avatar_set_parameter(avatar.p, 999, 1.0f), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(error().find("softdeca_avatar_set_parameter"), std::string::npos) << error();
  std::string other = "unset";
  std::thread([&] { other = softdeca_last_error(); }).join();
  EXPECT_EQ(other, "");
  ASSERT_EQ(softdeca_avatar_reset_parameters(avatar.p), SOFTDECA_OK);
  EXPECT_EQ(error(), "");
}

}  // namespace
