// The constraint groups of phi† for one mesh and one parameter set: the soft tissue, muscle and
// connecting tets, skin and skull triangles, skull bending, skin targets and landmarks, with
// every weight resolved per element, plus what gravity and the bones need.
#pragma once

#include <memory>
#include <vector>

#include "sim/constraints.h"
#include "sim/constraints_target.h"
#include "sim/parameters.h"
#include "sim/projections.h"

namespace softdeca::sim {

// Static frames weigh each target by w; dynamic frames (eq. 9) by w / gamma, because the blended
// target gamma S_t + (1 - gamma) y merges the target term w |x - S_t|^2 with an inertia term of
// weight w (1 - gamma) / gamma (implicit Euler in projective dynamics, Bouaziz et al. 2014);
// at rest (y = x) the inertia term vanishes, so a constant target gives the static solution.
enum class TargetMode { kStatic, kDynamic };

struct Model {
  std::vector<std::unique_ptr<ConstraintGroup>> groups;  // projecting groups first, then targets
  std::vector<Eigen::Index> row_offset;                  // first row of each group
  Eigen::Index variable_rows = 0;                        // rows of the projecting groups
  Eigen::Index rows = 0;
  Eigen::Index skin_row = -1, landmark_row = -1;  // first row of the skin / landmark targets

  Positions scaled_rest;          // rest with the bones scaled
  std::vector<char> pinned;       // per vertex
  Eigen::VectorXd mass;           // per vertex (kg), from the soft and muscle tets
  Eigen::VectorXd skin_area;      // per skin point (m^2)
  // Dynamics coefficients (eq. 9) per skin point and per landmark (interpolated).
  Eigen::VectorXd skin_gamma, skin_beta, landmark_gamma, landmark_beta;
  std::vector<PointRow> landmark_rows;  // landmark l as a combination of simulated vertices
};

// Per-tet multipliers of the volume and strain weights (soft tissue, muscle; empty: 1), beyond
// the parameters' own ranges: the solver's stiffening of elements a solve left inverted.
struct TetStiffening {
  Eigen::VectorXd soft, muscle;
};

Model build_model(const SimulationMesh& mesh, const ParameterSet& params, TargetMode mode, StrainLimit strain,
                  const TetStiffening* stiffening = nullptr);

// Appends a group's rows (projecting groups must come before constant ones); empty groups are
// skipped.
void add_group(Model& model, std::unique_ptr<ConstraintGroup> group);

// Gravity load per vertex for the current parameters: m (s g d - g0 d0), where d0 is the
// capture direction (-Y at 1 g): the neutral already hangs under earth's gravity.
Positions gravity_forces(const Model& model, const ParameterSet& params);

// Unit gravity direction from gravity_tilt and gravity_azimuth.
Eigen::Vector3d gravity_direction(const ParameterSet& params);

// alpha of eq. 9 from the stored gamma and beta: gamma + 2 alpha - beta = 1.
inline double dynamics_alpha(double gamma, double beta) { return 0.5 * (1.0 - gamma + beta); }

}  // namespace softdeca::sim
