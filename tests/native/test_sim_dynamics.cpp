// Second-order dynamics through the blended target (eq. 9).
#include <gtest/gtest.h>

#include <random>

#include "core/error.h"
#include "sim/dynamics.h"
#include "sim_test_support.h"

using namespace sim_test;

TEST(SimDynamics, StoredParameterisationIsStableAndEquilibriumPreserving) {
  const auto& g = parameter_spec(Param::dyn_gamma);
  const auto& b = parameter_spec(Param::dyn_beta);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ug(g.minimum, g.maximum), ub(b.minimum, b.maximum);
  for (int i = 0; i < 10000; ++i) {
    // Every point of the sampling box, corners included.
    const double gamma = i < 4 ? (i & 1 ? g.maximum : g.minimum) : ug(rng);
    const double beta = i < 4 ? (i & 2 ? b.maximum : b.minimum) : ub(rng);
    const double alpha = dynamics_alpha(gamma, beta);
    EXPECT_NEAR(gamma + 2 * alpha - beta, 1.0, 1e-15);
    EXPECT_GE(alpha, 0);
    EXPECT_LE(alpha, 2);  // inside the paper's sampling range 0..2
    EXPECT_LT(dynamics_spectral_radius(gamma, beta), 1.0) << gamma << " " << beta;
  }
  // Outside the stored box the recursion can be unstable (why the box is what it is).
  EXPECT_GT(dynamics_spectral_radius(-0.2, 0.5), 1.0);
  EXPECT_GE(dynamics_spectral_radius(0.5, 1.0), 1.0);
}

TEST(SimDynamics, BlendOfAConstantSequenceIsConstant) {
  Positions S(3, 3);
  S.setRandom();
  const Eigen::VectorXd gamma = Eigen::VectorXd::Constant(3, 0.3), beta = Eigen::VectorXd::Constant(3, 0.7);
  EXPECT_LT((blend_targets(S, S, S, gamma, beta) - S).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(SimDynamics, ConstantTargetConvergesToTheStaticSolution) {
  const SimulationMesh mesh = small_head();
  SolverSettings s;
  s.tolerance = 1e-8;
  Simulator sim(mesh, s);
  sim.parameters().set("dyn_gamma", 0.4);
  sim.parameters().set("dyn_beta", 0.6);
  const FrameInput rest = input_with(rest_skin(mesh));
  const FrameInput pose = input_with(bump(rest_skin(mesh), 0.01));
  const Positions static_solution = sim.solve_static(pose).skin;
  sim.reset_dynamics();
  sim.step_dynamic(rest);
  double last = 0;
  for (int f = 0; f < 50; ++f) {  // oscillation decays by sqrt(beta) = 0.77 per frame
    const FrameResult r = sim.step_dynamic(pose);
    EXPECT_TRUE(r.stats.converged) << "frame " << f;
    last = max_distance(r.skin, static_solution);
  }
  EXPECT_LT(last, 1e-7);
  // A sequence that starts on the pose stays on the static solution from its first frame.
  sim.reset_dynamics();
  for (int f = 0; f < 5; ++f) EXPECT_LT(max_distance(sim.step_dynamic(pose).skin, static_solution), 1e-7);
}

TEST(SimDynamics, StepOvershootsThenSettlesWhenUnderdamped) {
  const SimulationMesh mesh = small_head();
  const FrameInput rest = input_with(rest_skin(mesh));
  const FrameInput pose = input_with(bump(rest_skin(mesh), 0.01));
  SolverSettings s;
  s.tolerance = 1e-8;
  // Track the front-most skin point along +Z.
  const Positions skin = rest_skin(mesh);
  Eigen::Index front = 0;
  skin.col(2).maxCoeff(&front);
  auto trajectory = [&](double gamma, double beta) {
    Simulator sim(mesh, s);
    sim.parameters().set("dyn_gamma", gamma);
    sim.parameters().set("dyn_beta", beta);
    const double settled = sim.solve_static(pose).skin(front, 2) - skin(front, 2);
    std::vector<FrameInput> frames(1, rest);
    frames.resize(40, pose);
    std::vector<double> z;
    for (const FrameResult& r : sim.solve_sequence(frames)) z.push_back((r.skin(front, 2) - skin(front, 2)) / settled);
    return z;  // 1 = the static response
  };
  // gamma = 0.5, beta = 0.6: alpha = 0.55, alpha^2 < beta: oscillating, decaying by sqrt(0.6).
  const std::vector<double> under = trajectory(0.5, 0.6);
  const double peak = *std::max_element(under.begin(), under.end());
  EXPECT_GT(peak, 1.1);
  EXPECT_GT(under[1], 0.0);
  EXPECT_NEAR(under.back(), 1.0, 1e-4);
  // gamma = 0.5, beta = 0: alpha = 0.25, real roots: approaches without overshoot.
  const std::vector<double> over = trajectory(0.5, 0.0);
  for (double v : over) EXPECT_LT(v, 1.0 + 1e-6);
  EXPECT_NEAR(over.back(), 1.0, 1e-4);
  // alpha > 0 lags behind the static response on the first moving frame.
  EXPECT_LT(over[1], 0.9);
}

TEST(SimDynamics, IndependentSequencesInParallelMatchSequential) {
  const SimulationMesh mesh = small_head();
  SolverSettings s;
  s.threads = 2;
  s.tolerance = 1e-8;
  Simulator sim(mesh, s);
  sim.parameters().set("dyn_gamma", 0.6);
  sim.parameters().set("dyn_beta", 0.3);
  std::vector<std::vector<FrameInput>> seqs(3);
  for (int q = 0; q < 3; ++q)
    for (int f = 0; f < 4; ++f) seqs[q].push_back(input_with(bump(rest_skin(mesh), 0.003 * (q + 1) * (f % 2))));
  const auto parallel = sim.solve_sequences(seqs);
  ASSERT_EQ(parallel.size(), 3u);
  for (int q = 0; q < 3; ++q) {
    const auto sequential = sim.solve_sequence(seqs[q]);
    for (int f = 0; f < 4; ++f)
      EXPECT_LT(max_distance(parallel[q][f].vertices, sequential[f].vertices), 1e-12) << q << " " << f;
  }
}

TEST(SimDynamics, PerPointCoefficientsLocaliseTheDynamics) {
  // Points with gamma = 1, beta = 0 follow their target at once; the others lag.
  const SimulationMesh mesh = small_head();
  Simulator sim(mesh);
  const Positions skin = rest_skin(mesh);
  Eigen::VectorXd gamma(mesh.skin_count());
  for (Eigen::Index i = 0; i < gamma.size(); ++i) gamma[i] = skin(i, 0) > 0 ? 1.0 : 0.1;
  sim.parameters().set_field("dyn_gamma", gamma);
  const FrameInput pose = input_with(bump(skin, 0.01));
  const Positions settled = sim.solve_static(pose).skin;
  sim.reset_dynamics();
  sim.step_dynamic(input_with(skin));
  const FrameResult r = sim.step_dynamic(pose);
  double lag_fast = 0, lag_slow = 0;
  for (Eigen::Index i = 0; i < gamma.size(); ++i) {
    if (skin(i, 2) < 0.07 || std::abs(skin(i, 0)) < 0.02) continue;
    const double lag = (settled.row(i) - r.skin.row(i)).norm() / std::max(1e-9, (settled.row(i) - skin.row(i)).norm());
    (gamma[i] == 1.0 ? lag_fast : lag_slow) = std::max(gamma[i] == 1.0 ? lag_fast : lag_slow, lag);
  }
  EXPECT_GT(lag_slow, 0.5);
  EXPECT_LT(lag_fast, lag_slow);
}

TEST(SimDynamics, DynamicTargetIsTheBlendTheNextStepSolvesToward) {
  const SimulationMesh mesh = small_head();
  Simulator sim(mesh);
  const Positions skin = rest_skin(mesh);
  Eigen::VectorXd gamma(mesh.skin_count());
  for (Eigen::Index i = 0; i < gamma.size(); ++i) gamma[i] = skin(i, 0) > 0 ? 0.9 : 0.2;
  sim.parameters().set_field("dyn_gamma", gamma);
  sim.parameters().set("dyn_beta", 0.3);
  const Positions pose = bump(skin, 0.01);
  // Before the first frame a step is static: its target is the input itself.
  EXPECT_EQ(max_distance(sim.dynamic_skin_target(pose), pose), 0.0);
  const Positions t1 = sim.step_dynamic(input_with(skin)).skin;
  const Positions t2 = sim.step_dynamic(input_with(pose)).skin;
  // After two frames: gamma S + 2 alpha T_{t-1} - beta T_{t-2}, point by point.
  const Positions expected = blend_targets(pose, t2, t1, gamma, Eigen::VectorXd::Constant(gamma.size(), 0.3));
  const Positions target = sim.dynamic_skin_target(pose);
  EXPECT_LT(max_distance(target, expected), 1e-12);
  EXPECT_GT(max_distance(target, pose), 1e-4);  // the slow points lag
  // Asking changes nothing: the next step is the one it would have been.
  Simulator twin(mesh);
  twin.parameters().set_field("dyn_gamma", gamma);
  twin.parameters().set("dyn_beta", 0.3);
  twin.step_dynamic(input_with(skin));
  twin.step_dynamic(input_with(pose));
  EXPECT_LT(max_distance(sim.step_dynamic(input_with(pose)).skin, twin.step_dynamic(input_with(pose)).skin), 1e-12);
  EXPECT_THROW(sim.dynamic_skin_target(Positions(2, 3)), softdeca::Error);
}

TEST(SimDynamics, ContactsAreInelastic) {
  // Three points: one hit a contact while moving into it (-Y, shifted back +Y), one was
  // shifted while already moving away, one was not touched.
  Positions previous(3, 3), skin(3, 3), shift = Positions::Zero(3, 3);
  previous << 0, 0.010, 0, 1, 0, 0, 2, 0, 0;
  skin << 0.002, 0.006, 0, 1, 0.003, 0, 2.001, 0.002, 0;  // after the contact step
  shift.row(0) << 0, 0.002, 0;  // before it: (0.002, 0.004, 0), 6 mm down, 2 mm across
  shift.row(1) << 0, 0.001, 0;  // before it: (1, 0.002, 0), already moving up
  const Positions out = inelastic_previous(skin, shift, previous);
  // Velocity into the contact is gone, the sliding part is kept, the place is the corrected one.
  const Eigen::RowVector3d v0 = skin.row(0) - out.row(0);
  EXPECT_NEAR(v0.x(), 0.002, 1e-15);
  EXPECT_NEAR(v0.y(), 0.0, 1e-15);
  // Moving away: the velocity before the contact is kept (the shift does not add to it).
  const Eigen::RowVector3d v1 = skin.row(1) - out.row(1);
  EXPECT_NEAR(v1.y(), 0.002, 1e-15);
  // Untouched: T_{t-1} as it was.
  EXPECT_EQ(out.row(2), previous.row(2));
}
