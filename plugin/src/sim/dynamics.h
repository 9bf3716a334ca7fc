// Second-order dynamics through the blended target of eq. 9:
//   T_t = phi†(gamma S_t + 2 alpha T_{t-1} - beta T_{t-2}),   per skin point (and landmark).
// Stored parameters are gamma and beta; alpha = (1 - gamma + beta) / 2, so the coefficients
// sum to one (gamma + 2 alpha - beta = 1). With gamma in (0, 1] and beta in [0, 1) the
// recursion's characteristic roots z^2 - 2 alpha z + beta lie inside the unit circle
// (|beta| < 1 and 2 alpha < 1 + beta <=> gamma > 0): stable. Because the blend is an affine
// combination and the target weight is w / gamma (see TargetMode), a constant S_t gives a
// constant T_t equal to the static solution phi†(S_t). Oscillation (overshoot) when
// alpha^2 < beta; settles by a factor sqrt(beta) per frame.
#pragma once

#include "sim/mesh.h"

namespace softdeca::sim {

struct DynamicsHistory {
  Positions skin1, skin2;          // T_{t-1}, T_{t-2} at the skin points
  Positions landmark1, landmark2;  // the same at the landmarks
  Positions vertices;              // last frame's vertices (warm start)
  long frames = 0;
};

// gamma S + 2 alpha T1 - beta T2 row by row.
Positions blend_targets(const Positions& S, const Positions& T1, const Positions& T2, const Eigen::VectorXd& gamma,
                        const Eigen::VectorXd& beta);

// Characteristic roots' largest modulus of the recursion for one (gamma, beta).
double dynamics_spectral_radius(double gamma, double beta);

// T_{t-1} for the next frame's blend after the contact step moved skin points by `shift`
// (T_t = skin includes it): contacts are inelastic. A moved point keeps its corrected place,
// and its velocity T_t - T_{t-1} loses the part that ran into the contact (along the shift),
// so the momentum term neither carries the correction on nor pushes the point back in;
// velocity away from the contact is kept. Unmoved points keep `previous`.
Positions inelastic_previous(const Positions& skin, const Positions& shift, const Positions& previous);

}  // namespace softdeca::sim
