// The simulator through the public C header only (plus the synthetic mesh to fill it).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/synthetic.h"
#include "softdeca/softdeca.h"

namespace {
using namespace softdeca::sim;

// A synthetic head flattened into the C structs, the arrays owned here.
struct CMesh {
  std::vector<float> vertices, skin_weights;
  std::vector<int32_t> soft, muscle, connecting, skull, cranium, jaw, skin_vertices, skin_triangles;
  softdeca_sim_mesh desc{};

  explicit CMesh(const SimulationMesh& m) {
    for (Eigen::Index i = 0; i < m.rest.size(); ++i) vertices.push_back(static_cast<float>(m.rest.data()[i]));
    auto flat = [](const auto& idx, std::vector<int32_t>& out) { out.assign(idx.data(), idx.data() + idx.size()); };
    flat(m.soft_tets, soft);
    flat(m.muscle_tets, muscle);
    flat(m.connecting_tets, connecting);
    flat(m.skull_triangles, skull);
    flat(m.skin.vertex, skin_vertices);
    flat(m.skin_triangles, skin_triangles);
    for (Eigen::Index i = 0; i < m.skin.weight.size(); ++i) skin_weights.push_back(static_cast<float>(m.skin.weight.data()[i]));
    // float weights: renormalise so each row sums to one in float.
    for (std::size_t i = 0; i < skin_weights.size(); i += 4) {
      const float s = skin_weights[i] + skin_weights[i + 1] + skin_weights[i + 2] + skin_weights[i + 3];
      for (int k = 0; k < 4; ++k) skin_weights[i + static_cast<std::size_t>(k)] /= s;
    }
    cranium = m.cranium.vertices;
    jaw = m.jaw.vertices;
    desc.struct_size = sizeof(desc);
    desc.vertices = vertices.data();
    desc.vertex_count = static_cast<size_t>(m.rest.rows());
    desc.soft_tets = soft.data();
    desc.soft_tet_count = soft.size() / 4;
    desc.muscle_tets = muscle.data();
    desc.muscle_tet_count = muscle.size() / 4;
    desc.connecting_tets = connecting.data();
    desc.connecting_tet_count = connecting.size() / 4;
    desc.skull_triangles = skull.data();
    desc.skull_triangle_count = skull.size() / 3;
    desc.cranium_vertices = cranium.data();
    desc.cranium_vertex_count = cranium.size();
    desc.jaw_vertices = jaw.data();
    desc.jaw_vertex_count = jaw.size();
    desc.cranium_pinned = desc.jaw_pinned = 1;
    desc.skin_vertices = skin_vertices.data();
    desc.skin_weights = skin_weights.data();
    desc.skin_count = skin_vertices.size() / 4;
    desc.skin_triangles = skin_triangles.data();
    desc.skin_triangle_count = skin_triangles.size() / 3;
  }
};

SimulationMesh head() {
  SyntheticHeadOptions o;
  o.subdivisions = 2;
  o.skin_subdivisions = 2;
  return synthetic_layered_head(o);
}

std::string last_error() { return softdeca_last_error(); }

// A simulator parameter's index by name (the ABI addresses parameters by index).
uint32_t param(const char* name) {
  uint32_t index = 0;
  EXPECT_EQ(softdeca_sim_find_parameter(name, &index), SOFTDECA_OK) << name;
  return index;
}
}  // namespace

class SimCAbi : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(softdeca_sim_create(&mesh.desc, nullptr, &sim), SOFTDECA_OK) << last_error();
    ASSERT_EQ(softdeca_sim_get_skin_count(sim, &skin_count), SOFTDECA_OK);
    ASSERT_EQ(softdeca_sim_get_vertex_count(sim, &vertex_count), SOFTDECA_OK);
    rest_skin.resize(skin_count * 3);
    ASSERT_EQ(softdeca_sim_get_skin(sim, rest_skin.data(), skin_count), SOFTDECA_OK);
    frame.struct_size = sizeof(frame);
    frame.skin_targets = rest_skin.data();
    frame.skin_count = skin_count;
    stats.struct_size = sizeof(stats);
  }
  void TearDown() override { softdeca_sim_destroy(sim); }

  CMesh mesh{head()};
  softdeca_sim* sim = nullptr;
  uint32_t skin_count = 0, vertex_count = 0;
  std::vector<float> rest_skin;
  softdeca_sim_frame frame{};
  softdeca_sim_stats stats{};
};

TEST_F(SimCAbi, EnumeratesTheParameters) {
  uint32_t n = 0;
  ASSERT_EQ(softdeca_sim_get_parameter_count(&n), SOFTDECA_OK);
  ASSERT_GT(n, 20u);
  softdeca_parameter_info info{};
  info.struct_size = sizeof(info);
  bool found = false;
  for (uint32_t i = 0; i < n; ++i) {
    ASSERT_EQ(softdeca_sim_get_parameter_info(i, &info), SOFTDECA_OK);
    if (std::string(info.name) == "w_soft_volume") {
      found = true;
      EXPECT_EQ(param("w_soft_volume"), i);
      EXPECT_EQ(info.log_scale, SOFTDECA_TRUE);
      EXPECT_STREQ(info.domain, "soft_tet");
      EXPECT_STREQ(info.unit, "kPa");
    }
  }
  EXPECT_TRUE(found);
  EXPECT_EQ(softdeca_sim_get_parameter_info(n, &info), SOFTDECA_ERROR_INVALID_ARGUMENT);
  uint32_t index = 7;
  EXPECT_EQ(softdeca_sim_find_parameter("nope", &index), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(index, 7u);
  EXPECT_EQ(softdeca_sim_find_parameter(nullptr, &index), SOFTDECA_ERROR_INVALID_ARGUMENT);
  const char* json = nullptr;
  ASSERT_EQ(softdeca_sim_get_parameters_json(&json), SOFTDECA_OK);
  EXPECT_NE(std::string(json).find("\"w_soft_volume\""), std::string::npos);
}

TEST_F(SimCAbi, SolvesAndReadsBack) {
  // A bump pulls the front out; the result follows it.
  std::vector<float> target = rest_skin;
  for (size_t i = 0; i < skin_count; ++i)
    if (target[3 * i + 2] > 0.05f) target[3 * i + 2] += 0.004f;
  frame.skin_targets = target.data();
  ASSERT_EQ(softdeca_sim_set_parameter(sim, param("w_soft_strain"), 2.0), SOFTDECA_OK) << last_error();
  double v = 0;
  ASSERT_EQ(softdeca_sim_get_parameter(sim, param("w_soft_strain"), &v), SOFTDECA_OK);
  EXPECT_EQ(v, 2.0);
  ASSERT_EQ(softdeca_sim_solve_static(sim, &frame, &stats), SOFTDECA_OK) << last_error();
  EXPECT_EQ(stats.converged, SOFTDECA_TRUE);
  EXPECT_GT(stats.iterations, 0u);
  std::vector<float> skin(skin_count * 3), verts(vertex_count * 3);
  ASSERT_EQ(softdeca_sim_get_skin(sim, skin.data(), skin_count), SOFTDECA_OK);
  ASSERT_EQ(softdeca_sim_get_vertices(sim, verts.data(), vertex_count), SOFTDECA_OK);
  double moved = 0;
  for (size_t i = 0; i < skin_count; ++i)
    if (rest_skin[3 * i + 2] > 0.05f) moved = std::max(moved, static_cast<double>(skin[3 * i + 2] - rest_skin[3 * i + 2]));
  EXPECT_GT(moved, 0.002);
  // The figures a frame's sanity check reads: the largest distance of S to its target (S's
  // own, to float precision) and no inverted tet.
  double largest = 0;
  for (size_t i = 0; i < skin_count; ++i) {
    double d2 = 0;
    for (int c = 0; c < 3; ++c) d2 += std::pow(static_cast<double>(skin[3 * i + c]) - target[3 * i + c], 2);
    largest = std::max(largest, std::sqrt(d2));
  }
  EXPECT_GT(stats.max_target_distance, 0.0);
  EXPECT_NEAR(stats.max_target_distance, largest, 1e-6);
  EXPECT_EQ(stats.inverted_elements, 0u);
  EXPECT_EQ(stats.rejected_collision_rounds, 0u);

  // Dynamic steps and a batch through the same handle.
  ASSERT_EQ(softdeca_sim_set_parameter(sim, param("dyn_gamma"), 0.5), SOFTDECA_OK);
  ASSERT_EQ(softdeca_sim_reset_dynamics(sim), SOFTDECA_OK);
  ASSERT_EQ(softdeca_sim_step_dynamic(sim, &frame, nullptr), SOFTDECA_OK) << last_error();
  ASSERT_EQ(softdeca_sim_step_dynamic(sim, &frame, &stats), SOFTDECA_OK) << last_error();
  softdeca_sim_frame frames[2] = {frame, frame};
  frames[0].skin_targets = rest_skin.data();
  std::vector<float> out(2 * skin_count * 3);
  softdeca_sim_stats bstats[2] = {stats, stats};
  ASSERT_EQ(softdeca_sim_solve_static_batch(sim, frames, 2, out.data(), 2 * skin_count, bstats), SOFTDECA_OK)
      << last_error();
  EXPECT_NEAR(out[0], rest_skin[0], 1e-6);
}

TEST_F(SimCAbi, RefusesBadInputAndKeepsTheLastGoodOutput) {
  std::vector<float> before(skin_count * 3), after(skin_count * 3);
  ASSERT_EQ(softdeca_sim_get_skin(sim, before.data(), skin_count), SOFTDECA_OK);

  std::vector<float> nan_target = rest_skin;
  nan_target[5] = NAN;
  frame.skin_targets = nan_target.data();
  EXPECT_EQ(softdeca_sim_solve_static(sim, &frame, &stats), SOFTDECA_ERROR_NON_FINITE);
  EXPECT_NE(last_error().find("skin_targets[5]"), std::string::npos) << last_error();
  frame.skin_targets = rest_skin.data();

  frame.skin_count = skin_count - 1;
  EXPECT_EQ(softdeca_sim_solve_static(sim, &frame, &stats), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(last_error().find("skin_count"), std::string::npos) << last_error();
  frame.skin_count = skin_count;

  EXPECT_EQ(softdeca_sim_set_parameter(sim, param("max_strain"), 2.0), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(last_error().find("outside its range [0.7, 1.3]"), std::string::npos) << last_error();
  uint32_t count = 0;
  ASSERT_EQ(softdeca_sim_get_parameter_count(&count), SOFTDECA_OK);
  EXPECT_EQ(softdeca_sim_set_parameter(sim, count, 1.0), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(last_error().find("not below"), std::string::npos) << last_error();
  const float few[2] = {1, 1};
  EXPECT_EQ(softdeca_sim_set_parameter_field(sim, param("w_target"), few, 2), SOFTDECA_ERROR_INVALID_ARGUMENT);

  const float shear[12] = {1, 0.5f, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  frame.jaw_transform = shear;
  EXPECT_EQ(softdeca_sim_solve_static(sim, &frame, &stats), SOFTDECA_ERROR_INVALID_ARGUMENT);
  frame.jaw_transform = nullptr;

  softdeca_sim_frame old = frame;
  old.struct_size = sizeof(frame) - 8;
  EXPECT_EQ(softdeca_sim_solve_static(sim, &old, &stats), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_sim_solve_static(nullptr, &frame, &stats), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_sim_solve_static(sim, nullptr, &stats), SOFTDECA_ERROR_INVALID_ARGUMENT);

  std::vector<float> small(3);
  EXPECT_EQ(softdeca_sim_get_skin(sim, small.data(), 1), SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  ASSERT_EQ(softdeca_sim_get_skin(sim, after.data(), skin_count), SOFTDECA_OK);
  EXPECT_EQ(before, after);
}

TEST(SimCAbiCreate, RefusesBrokenMeshes) {
  CMesh m(head());
  softdeca_sim* sim = nullptr;
  EXPECT_EQ(softdeca_sim_create(nullptr, nullptr, &sim), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_sim_create(&m.desc, nullptr, nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
  m.soft[5] = 1 << 20;
  EXPECT_EQ(softdeca_sim_create(&m.desc, nullptr, &sim), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(last_error().find("soft_tets[1] refers to index"), std::string::npos) << last_error();
  m.soft[5] = m.soft[4];
  m.vertices[0] = INFINITY;
  EXPECT_EQ(softdeca_sim_create(&m.desc, nullptr, &sim), SOFTDECA_ERROR_NON_FINITE);
  m.vertices[0] = 0;
  m.desc.soft_tets = nullptr;
  EXPECT_EQ(softdeca_sim_create(&m.desc, nullptr, &sim), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(sim, nullptr);

  CMesh ok(head());
  softdeca_sim_settings s{};
  s.struct_size = sizeof(s);
  ASSERT_EQ(softdeca_sim_settings_init(&s), SOFTDECA_OK);
  s.tolerance = -1;
  EXPECT_EQ(softdeca_sim_create(&ok.desc, &s, &sim), SOFTDECA_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(softdeca_sim_settings_init(&s), SOFTDECA_OK);
  s.tolerance = NAN;
  EXPECT_EQ(softdeca_sim_create(&ok.desc, &s, &sim), SOFTDECA_ERROR_NON_FINITE);
  ASSERT_EQ(softdeca_sim_settings_init(&s), SOFTDECA_OK);
  ASSERT_EQ(softdeca_sim_create(&ok.desc, &s, &sim), SOFTDECA_OK) << last_error();
  softdeca_sim_destroy(sim);
  softdeca_sim_destroy(nullptr);
}
