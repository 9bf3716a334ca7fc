// softdeca_stats.frame_bytes, the least bytes a frame reads and writes in memory: exact sums of
// known sizes on the runtime test data (a small random bundle, its 186-vertex head) with
// blendshapes laid out so that their stored runs are known, for every kind of frame.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "bundle/manifest.h"
#include "bundle/onnx_model_scan.h"
#include "runtime/deformation_transfer.h"
#include "runtime_fixture.h"

namespace {
using namespace rt;
using namespace softdeca::runtime;
using namespace softdeca::bundle;

constexpr std::uint64_t kVertex = 12;  // xyz float
constexpr std::uint64_t kRun = 12;     // a blendshape run's first vertex, count and offset (uint32 each)
constexpr std::uint64_t kLanes = 8;    // elements per hyper-tensor block

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::uint64_t blocks(std::uint64_t elements) { return (elements + kLanes - 1) / kLanes; }

class FrameBytes : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_TEST_DATA();
    head = Head::load();
    bundle = data_dir() + "/bundle";
    manifest = parse_manifest(read_file(bundle + "/manifest.json"));
    ASSERT_EQ(softdeca_model_load(bundle.c_str(), nullptr, &model.p), SOFTDECA_OK) << softdeca_last_error();
    vh = head.vertices();
    vs = static_cast<std::uint64_t>(manifest.skin_vertices);
    ASSERT_EQ(vh, 186u);
    ASSERT_EQ(vs, 162u);
    // Shape 3 moves vertices 10-19 and 26-29 (six unmoved between: two runs); shape 24 moves
    // 50-99 and 103-149 (three unmoved between: one run of 100, the gap stored as zeros);
    // shape 7 moves every vertex but has weight 0 in the frames below.
    head.blendshapes.assign(52 * vh * 3, 0.0f);
    const auto move = [&](std::size_t shape, std::size_t v0, std::size_t v1) {
      for (std::size_t v = v0; v < v1; ++v) head.blendshapes[(shape * vh + v) * 3 + 1] = 0.001f;
    };
    move(3, 10, 20);
    move(3, 26, 30);
    move(24, 50, 100);
    move(24, 103, 150);
    move(7, 0, vh);
    const auto d = describe(head);
    ASSERT_EQ(softdeca_avatar_create(model.p, &d, &avatar.p), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_avatar_prepare(avatar.p), SOFTDECA_OK);
    weights.assign(52, 0.0f);
    weights[3] = 0.4f;
    weights[24] = 0.7f;
  }

  std::uint64_t network_weights(const std::string& key) const {
    const NetworkSpec& spec = manifest.networks.at(key);
    const std::string bytes = read_file(bundle + "/" + spec.file);
    return scan_onnx_model(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), spec.inputs).weight_bytes;
  }
  // The neutral read, the two moved shapes' runs and deltas.
  std::uint64_t blend() const { return vh * kVertex + (2 * kRun + 14 * kVertex) + (kRun + 100 * kVertex); }
  // The host's triangles, the vertex-to-triangle lists, the normals written.
  std::uint64_t normals() const {
    const std::uint64_t t = head.triangles.size() / 3;
    return (3 * t + (vh + 1) + 3 * t) * 4 + vh * kVertex;
  }
  // Half precision: blocks of 8 elements x latent x width, 2 bytes each.
  std::uint64_t half_tensor(std::uint64_t elements, std::uint64_t width) const {
    return blocks(elements) * kLanes * static_cast<std::uint64_t>(manifest.latent) * width * 2;
  }
  // DT's factor on one thread: values (float) and row indices (uint16) per nonzero, column
  // starts, the permutation and the diagonal (double).
  std::uint64_t factor() const {
    const std::string tri = read_file(bundle + "/" + manifest.skin_triangles_file);
    std::vector<std::int32_t> triangles(tri.size() / 4);
    std::memcpy(triangles.data(), tri.data(), tri.size());
    const SkinGeometry g = SkinGeometry::measure(head.neutral.data(), vs, triangles);
    const DeformationTransfer dt(g, vs, triangles, manifest.dt_regularisation, 1);
    const std::uint64_t n = dt.vertices(), nnz = dt.factor_nonzeros();
    return nnz * (4 + 2) + (n + 1) * 4 + n * 4 + n * 8;
  }

  std::uint64_t last() const {
    softdeca_stats s{};
    s.struct_size = sizeof s;
    EXPECT_EQ(softdeca_avatar_get_stats(avatar.p, &s), SOFTDECA_OK);
    return s.frame_bytes;
  }

  Head head;
  std::string bundle;
  Manifest manifest;
  ModelPtr model;
  AvatarPtr avatar;
  std::uint64_t vh = 0, vs = 0;
  std::vector<float> weights;
};

TEST_F(FrameBytes, LinearBlendReadsTheMovedShapesOnly) {
  Buffers b(vh);
  ASSERT_EQ(softdeca_avatar_evaluate_linear(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  EXPECT_EQ(last(), blend() + vh * kVertex + normals());
  // Without normals; and shape 7 moved too: all its 186 vertices in one run.
  b.out.normals = nullptr;
  ASSERT_EQ(softdeca_avatar_evaluate_linear(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  EXPECT_EQ(last(), blend() + vh * kVertex);
  weights[7] = 0.1f;
  ASSERT_EQ(softdeca_avatar_evaluate_linear(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  EXPECT_EQ(last(), blend() + kRun + vh * kVertex + vh * kVertex);
}

TEST_F(FrameBytes, SoftDecaAddsItsNetworkHyperTensorFactorAndDynamics) {
  const std::uint64_t nf = static_cast<std::uint64_t>(manifest.skin_triangles);
  // f_w; L over the faces (width 9) and the right-hand side's face blocks (3 corners, 3
  // metric coefficients, 8 lanes each); the factor; the head written; normals.
  const std::uint64_t dt = half_tensor(nf, 9) + blocks(nf) * (3 * kLanes * 4 + 3 * kLanes * 4);
  const std::uint64_t fixed = network_weights("softdeca.f_w") + dt + factor() + vh * kVertex + normals();
  EXPECT_GT(network_weights("softdeca.f_w"), 0u);
  Buffers b(vh);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  EXPECT_EQ(last(), blend() + fixed);
  // Dynamics: alpha, beta, gamma per skin vertex; the two previous states and the new one.
  ASSERT_EQ(softdeca_avatar_set_dynamics(avatar.p, SOFTDECA_TRUE), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  EXPECT_EQ(last(), blend() + fixed + 3 * vs * 4 + 3 * vs * kVertex);
  ASSERT_EQ(softdeca_avatar_set_dynamics(avatar.p, SOFTDECA_FALSE), SOFTDECA_OK);
  // The caller's skin instead of the blend; the non-skin vertices then follow the bones, read
  // from the neutral.
  const std::vector<float> skin(head.neutral.begin(), head.neutral.begin() + static_cast<std::ptrdiff_t>(vs * 3));
  ASSERT_EQ(softdeca_avatar_evaluate_surface(avatar.p, weights.data(), 52, skin.data(), static_cast<uint32_t>(vs), &b.out),
            SOFTDECA_OK);
  EXPECT_EQ(last(), vs * kVertex + fixed + (vh - vs) * kVertex);
}

TEST_F(FrameBytes, SparseReadsItsNetworkTensorAndTheNeutral) {
  softdeca_model_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(softdeca_model_get_info(model.p, &info), SOFTDECA_OK);
  std::vector<float> landmarks(3 * info.landmark_count, 0.01f);
  Buffers b(vh);
  ASSERT_EQ(softdeca_avatar_evaluate_landmarks(avatar.p, landmarks.data(), info.landmark_count, &b.out), SOFTDECA_OK);
  // f_l; L over the skin vertices (width 3) and the neutral skin it offsets; the head written,
  // its non-skin vertices read from the neutral; normals.
  EXPECT_EQ(last(), network_weights("sparse.f_l") + half_tensor(vs, 3) + vs * kVertex + vh * kVertex + (vh - vs) * kVertex +
                        normals());
}

TEST_F(FrameBytes, TheRestOffsetIsReadAwayFromTheDefaults) {
  uint32_t gravity = 0;
  ASSERT_EQ(softdeca_model_find_parameter(model.p, "gravity_strength", &gravity), SOFTDECA_OK);
  Buffers b(vh);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  const std::uint64_t at_defaults = last();
  ASSERT_EQ(softdeca_avatar_set_parameter(avatar.p, gravity, 2.0), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_prepare(avatar.p), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, weights.data(), 52, &b.out), SOFTDECA_OK);
  EXPECT_EQ(last(), at_defaults + vs * kVertex);
}

}  // namespace
