// Shared helpers of the simulator tests: small synthetic layered heads and measurements.
#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "sim/simulator.h"
#include "sim/synthetic.h"

namespace sim_test {
using namespace softdeca::sim;

inline SimulationMesh small_head(bool pinned = true, int landmark_stride = 0, int subdivisions = 2) {
  SyntheticHeadOptions o;
  o.subdivisions = subdivisions;
  o.skin_subdivisions = subdivisions + 1;
  o.pin_bones = pinned;
  o.landmark_stride = landmark_stride;
  return synthetic_layered_head(o);
}

inline Positions rest_skin(const SimulationMesh& m) { return embed(m.skin, m.rest); }

inline FrameInput input_with(const Positions& skin_targets) {
  FrameInput in;
  in.skin_targets = skin_targets;
  return in;
}

// Skin targets pushed along the radial direction by `amount` * max(0, n.z)^2 (a bump on the
// face side, +Z).
inline Positions bump(const Positions& skin, double amount) {
  Positions t = skin;
  for (Eigen::Index i = 0; i < t.rows(); ++i) {
    const Eigen::Vector3d n = skin.row(i).transpose().normalized();
    const double w = std::max(0.0, n.z());
    t.row(i) += amount * w * w * n.transpose();
  }
  return t;
}

// Total signed volume of a tet set.
inline double volume(const Positions& x, const TetIndices& tets) {
  double v = 0;
  for (Eigen::Index t = 0; t < tets.rows(); ++t) {
    const Eigen::Vector3d a = x.row(tets(t, 0)), b = x.row(tets(t, 1)), c = x.row(tets(t, 2)), d = x.row(tets(t, 3));
    v += (b - a).dot((c - a).cross(d - a)) / 6.0;
  }
  return v;
}

inline Positions transformed(const Positions& x, const Eigen::Isometry3d& T) {
  Positions y(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) y.row(i) = (T * x.row(i).transpose()).transpose();
  return y;
}

inline double max_distance(const Positions& a, const Positions& b) { return (a - b).rowwise().norm().maxCoeff(); }

// Energy history never rises (beyond rounding).
inline bool monotone(const std::vector<double>& e) {
  for (std::size_t i = 1; i < e.size(); ++i)
    if (e[i] > e[i - 1] + 1e-11 * std::abs(e[i - 1])) return false;
  return true;
}

}  // namespace sim_test
