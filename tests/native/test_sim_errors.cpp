// Bad input to the simulator gives a clear error, never a crash or a silent wrong answer.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "sim_test_support.h"

using namespace sim_test;
using softdeca::Error;

namespace {
// Runs f, expects an Error with `status` whose message contains `text`.
template <class F>
void expect_error(F&& f, softdeca_status status, const std::string& text) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one containing '" << text << "'";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), status) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(SimErrors, NonFiniteTargetIsRefused) {
  const SimulationMesh mesh = small_head();
  Simulator sim(mesh);
  Positions t = rest_skin(mesh);
  t(7, 1) = std::nan("");
  expect_error([&] { sim.solve_static(input_with(t)); }, SOFTDECA_ERROR_NON_FINITE, "skin_targets[7][1]");
  t(7, 1) = INFINITY;
  expect_error([&] { sim.step_dynamic(input_with(t)); }, SOFTDECA_ERROR_NON_FINITE, "skin_targets[7][1]");
  FrameInput in = input_with(rest_skin(mesh));
  in.warm_start = mesh.rest;
  in.warm_start(3, 0) = std::nan("");
  expect_error([&] { sim.solve_static(in); }, SOFTDECA_ERROR_NON_FINITE, "warm_start[3][0]");
}

TEST(SimErrors, WrongSizesAreRefused) {
  const SimulationMesh mesh = small_head();
  Simulator sim(mesh);
  expect_error([&] { sim.solve_static(input_with(rest_skin(mesh).topRows(10))); }, SOFTDECA_ERROR_INVALID_ARGUMENT,
               "skin_targets has 10 rows, expected");
  FrameInput in = input_with(rest_skin(mesh));
  in.landmark_targets = Positions::Zero(4, 3);  // this mesh has no landmarks
  expect_error([&] { sim.solve_static(in); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "landmark_targets has 4 rows, expected 0");
  in = input_with(rest_skin(mesh));
  in.warm_start = mesh.rest.topRows(5);
  expect_error([&] { sim.solve_static(in); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "warm_start has 5 rows");
  const SimulationMesh with_landmarks = small_head(true, 5);
  Simulator sparse(with_landmarks);
  expect_error([&] { sparse.solve_static(input_with(rest_skin(with_landmarks))); }, SOFTDECA_ERROR_INVALID_ARGUMENT,
               "landmark_targets has 0 rows");
}

TEST(SimErrors, OutOfRangeParameterIsRefusedAndNothingChanges) {
  const SimulationMesh mesh = small_head();
  Simulator sim(mesh);
  expect_error([&] { sim.parameters().set("gravity_strength", 3.0); }, SOFTDECA_ERROR_INVALID_ARGUMENT,
               "'gravity_strength' = 3 is outside its range [0, 2]");
  EXPECT_EQ(sim.parameters().global(Param::gravity_strength), 1.0);
  expect_error([&] { sim.parameters().set_field("w_target", Eigen::VectorXd::Ones(3)); },
               SOFTDECA_ERROR_INVALID_ARGUMENT, "skin_point has " + std::to_string(mesh.skin_count()));
}

TEST(SimErrors, BadTransformsAreRefused) {
  const SimulationMesh mesh = small_head();
  Simulator sim(mesh);
  FrameInput in = input_with(rest_skin(mesh));
  in.bones.jaw.linear() *= 1.1;  // not a rigid motion
  expect_error([&] { sim.solve_static(in); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "jaw transform is not a rigid motion");
  in.bones.jaw = Eigen::Isometry3d::Identity();
  in.bones.cranium.translation().x() = std::nan("");
  expect_error([&] { sim.solve_static(in); }, SOFTDECA_ERROR_NON_FINITE, "cranium transform is not finite");
}

TEST(SimErrors, BrokenMeshesAreRefusedWithTheFirstProblem) {
  const SimulationMesh good = small_head();
  SimulationMesh m = good;
  std::swap(m.soft_tets(4, 2), m.soft_tets(4, 3));
  expect_error([&] { Simulator s(m); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "soft_tets[4] is inverted");
  m = good;
  m.muscle_tets(2, 1) = static_cast<int32_t>(m.rest.rows());
  expect_error([&] { Simulator s(m); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "muscle_tets[2] refers to index");
  m = good;
  m.skin.weight(3, 0) += 0.5;
  expect_error([&] { Simulator s(m); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "skin.weight[3] weights sum to");
  m = good;
  m.rest(0, 0) = std::nan("");
  expect_error([&] { Simulator s(m); }, SOFTDECA_ERROR_NON_FINITE, "rest positions are not finite");
  m = good;
  m.jaw.vertices.push_back(m.cranium.vertices.front());
  expect_error([&] { Simulator s(m); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "listed twice in the bones");
  m = good;
  m.skin_triangles.resize(0, 3);
  expect_error([&] { Simulator s(m); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "need skin_triangles or skin_point_area");
  m = good;
  m.rest.conservativeResize(m.rest.rows() + 1, 3);
  m.rest.bottomRows(1).setZero();
  expect_error([&] { Simulator s(m); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "belongs to no tet");
}

TEST(SimErrors, BadSettingsAreRefused) {
  const SimulationMesh mesh = small_head();
  SolverSettings s;
  s.tolerance = 0;
  expect_error([&] { Simulator sim(mesh, s); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "tolerance");
  s = SolverSettings{};
  s.max_iterations = 0;
  expect_error([&] { Simulator sim(mesh, s); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "max_iterations");
  s = SolverSettings{};
  s.inversion_rounds = 11;
  expect_error([&] { Simulator sim(mesh, s); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "inversion_rounds");
  s = SolverSettings{};
  s.inversion_stiffening = 1.0;
  expect_error([&] { Simulator sim(mesh, s); }, SOFTDECA_ERROR_INVALID_ARGUMENT, "inversion_stiffening");
}
