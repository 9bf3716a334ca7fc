#include "sim/solver.h"

#include <Eigen/Dense>
#include <chrono>
#include <cmath>

#include "core/error.h"

namespace softdeca::sim {
namespace {
using Clock = std::chrono::steady_clock;
// Plain steps that measure the slowest mode's contraction before convergence is accepted:
// the ratios of the last four, a short power iteration (three steps measured a contraction
// far enough under the slowest mode's that results lay up to 3.4 times the tolerance away).
constexpr int kVerifySteps = 5;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Local step over every group: projections into P and the energy at x (with the external
// forces' potential -f.x).
double local_step(const FrameProblem& pr, const Positions& x, Positions& P, ThreadPool* pool) {
  const Model& m = *pr.model;
  const int workers = pool ? pool->size() : 1;
  std::vector<double> part(static_cast<std::size_t>(workers), 0.0);
  auto run_group = [&](const ConstraintGroup& g, Eigen::Index offset) {
    auto block = P.middleRows(offset, g.rows());
    auto body = [&](std::size_t b, std::size_t e, int w) {
      part[static_cast<std::size_t>(w)] += g.project(x, static_cast<Eigen::Index>(b), static_cast<Eigen::Index>(e), block);
    };
    const auto n = static_cast<std::size_t>(g.elements());
    if (pool && n > 256) pool->parallel_for(n, body);
    else body(0, n, 0);
  };
  for (std::size_t g = 0; g < m.groups.size(); ++g) run_group(*m.groups[g], m.row_offset[g]);
  if (pr.extra) run_group(*pr.extra, m.rows);
  double e = 0;
  for (double v : part) e += v;
  if (pr.force) e -= (pr.force->array() * x.array()).sum();
  return e;
}

// Anderson acceleration (type II, Walker and Ni 2011) of the fixed-point map x -> g(x).
class Anderson {
 public:
  Anderson(int window, Eigen::Index size) : m_(window), dg_(size, window), df_(size, window) {}
  void reset() { count_ = 0, has_prev_ = false; }
  // Takes g(x_k) and f_k = g(x_k) - x_k; returns the accelerated next iterate.
  Eigen::VectorXd next(const Eigen::VectorXd& g, const Eigen::VectorXd& f, bool& accelerated) {
    accelerated = false;
    if (has_prev_) {
      const int col = static_cast<int>(count_ % static_cast<std::size_t>(m_));
      dg_.col(col) = g - g_prev_;
      df_.col(col) = f - f_prev_;
      ++count_;
    }
    g_prev_ = g;
    f_prev_ = f;
    has_prev_ = true;
    const int k = static_cast<int>(std::min<std::size_t>(count_, static_cast<std::size_t>(m_)));
    if (k == 0) return g;
    const Eigen::MatrixXd F = df_.leftCols(k);
    Eigen::MatrixXd N = F.transpose() * F;
    N.diagonal().array() += 1e-12 * (N.diagonal().maxCoeff() + 1e-300);
    const Eigen::VectorXd theta = N.ldlt().solve(F.transpose() * f);
    if (!theta.allFinite()) return g;
    accelerated = true;
    return g - dg_.leftCols(k) * theta;
  }

 private:
  int m_;
  Eigen::MatrixXd dg_, df_;
  Eigen::VectorXd g_prev_, f_prev_;
  std::size_t count_ = 0;
  bool has_prev_ = false;
};

}  // namespace

void validate(const SolverSettings& s) {
  require(s.max_iterations >= 1 && s.max_iterations <= 100000, "max_iterations must be in [1, 100000]");
  require(std::isfinite(s.tolerance) && s.tolerance > 0 && s.tolerance < 1, "tolerance must be in (0, 1)");
  require(s.anderson_window >= 0 && s.anderson_window <= 50, "anderson_window must be in [0, 50]");
  require(std::isfinite(s.collision_weight) && s.collision_weight > 0, "collision_weight must be positive");
  require(s.collision_rounds >= 0 && s.collision_rounds <= 100, "collision_rounds must be in [0, 100]");
  require(std::isfinite(s.penetration_tolerance) && s.penetration_tolerance >= 0,
          "penetration_tolerance must be non-negative");
  require(s.inversion_rounds >= 0 && s.inversion_rounds <= 10, "inversion_rounds must be in [0, 10]");
  require(std::isfinite(s.inversion_stiffening) && s.inversion_stiffening > 1 && s.inversion_stiffening <= 1e3,
          "inversion_stiffening must be in (1, 1000]");
}

void run_projective_dynamics(const FrameProblem& pr, Positions& P, Positions& x, const SolverSettings& s,
                             ThreadPool* pool, SolveStats& stats) {
  const System& sys = *pr.system;
  const auto& free = sys.free_vertices();
  const Eigen::Index nf = sys.free_count();
  Positions zero_force;
  const Positions& force = pr.force ? *pr.force : (zero_force = Positions::Zero(x.rows(), 3));
  const Positions frame = sys.frame_rhs(P, x, force);

  auto t = Clock::now();
  double energy = local_step(pr, x, P, pool);
  stats.local_seconds += seconds_since(t);
  if (s.record_energy) stats.energy_history.push_back(energy);

  Anderson aa(s.anderson_window, 3 * nf);
  Positions x_free(nf, 3), rhs, g_free;
  for (Eigen::Index i = 0; i < nf; ++i) x_free.row(i) = x.row(free[static_cast<std::size_t>(i)]);
  const double scale = pr.length_scale * std::sqrt(static_cast<double>(nf));
  // Convergence: the distance to the fixed point is about residual / (1 - rho), with rho the
  // contraction of a plain PD step along its slowest mode. A small residual alone can hide a
  // slow mode (soft shear under a stiff volume term), so when the residual says "converged"
  // a few plain steps (no acceleration) measure rho as their residual ratio, a power
  // iteration on the slowest mode, and the estimate decides. The first plain step's ratio is
  // left out: it still carries the accelerated iterate's mixture of modes and can exceed 1
  // far above the arithmetic's floor, and rho, kept as the largest measured, would then hold
  // every later estimate at 10^5 times the residual.
  double rho = 0, previous_residual = -1;
  int verifying = 0;  // plain steps taken in the current verification, 0: not verifying
  stats.converged = false;
  for (int it = 0; it < s.max_iterations; ++it) {
    t = Clock::now();
    sys.iteration_rhs(P, frame, x_free, rhs, pool);
    sys.solve(rhs, g_free);
    stats.global_seconds += seconds_since(t);
    ++stats.iterations;
    const double residual = (g_free - x_free).norm() / scale;
    stats.relative_step = residual;
    if (!std::isfinite(residual))
      throw Error(SOFTDECA_ERROR_INTERNAL, "the projective dynamics iteration diverged (non-finite positions)");
    if (verifying > 1 && previous_residual > 0) rho = std::max(rho, std::min(residual / previous_residual, 0.99999));
    stats.contraction = rho;
    stats.estimated_error = residual / (1 - rho);
    const bool small = residual == 0 || residual < s.tolerance * (1 - rho);
    if (small && (residual == 0 || verifying >= kVerifySteps)) {
      x_free = g_free;
      for (Eigen::Index i = 0; i < nf; ++i) x.row(free[static_cast<std::size_t>(i)]) = x_free.row(i);
      stats.converged = true;
      break;
    }
    if (small && verifying == 0) aa.reset();  // start measuring with plain steps
    verifying = small || (verifying > 0 && verifying < kVerifySteps) ? verifying + 1 : 0;
    previous_residual = residual;
    // Candidate: the accelerated iterate, else the plain step.
    Positions candidate = g_free;
    bool accelerated = false;
    if (s.anderson_window > 0 && verifying == 0) {
      const Eigen::Map<const Eigen::VectorXd> g(g_free.data(), 3 * nf), xf(x_free.data(), 3 * nf);
      const Eigen::VectorXd next = aa.next(g, g - xf, accelerated);
      if (accelerated) candidate = Eigen::Map<const Positions>(next.data(), nf, 3);
    }
    Positions x_new = x;
    for (Eigen::Index i = 0; i < nf; ++i) x_new.row(free[static_cast<std::size_t>(i)]) = candidate.row(i);
    t = Clock::now();
    Positions P_new = P;
    double e_new = local_step(pr, x_new, P_new, pool);
    stats.local_seconds += seconds_since(t);
    if (accelerated && !(e_new <= energy + 1e-12 * std::abs(energy))) {
      // Safeguard: fall back to the plain PD step, which cannot raise the energy.
      ++stats.anderson_rejections;
      aa.reset();
      candidate = g_free;
      for (Eigen::Index i = 0; i < nf; ++i) x_new.row(free[static_cast<std::size_t>(i)]) = candidate.row(i);
      t = Clock::now();
      P_new = P;
      e_new = local_step(pr, x_new, P_new, pool);
      stats.local_seconds += seconds_since(t);
    }
    x.swap(x_new);
    P.swap(P_new);
    x_free = candidate;
    energy = e_new;
    if (s.record_energy) stats.energy_history.push_back(energy);
  }
  stats.energy = energy;
}
}  // namespace softdeca::sim
