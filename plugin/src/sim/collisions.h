// Lip and teeth collisions (paper 3.3.2), resolved after the solve by a further projective
// step as in Komaritzan and Botsch's projective skinning: each penetrating point is tied to
// the closest point of the surface it went through by a stiff constraint whose target is
// zero distance, so the two coincide and no gap opens between upper and lower lip.
#pragma once

#include <memory>
#include <vector>

#include "sim/constraints_target.h"
#include "sim/mesh.h"

namespace softdeca::sim {

struct Contact {
  int set;                  // index into mesh.collisions
  int32_t point;            // skin point
  int32_t triangle;         // row of the set's surface
  Eigen::Vector3d bary;     // closest point on that triangle
  double depth;             // how far behind the surface (m), positive when penetrating
};

// Points of every collision set that lie behind their surface by more than `tolerance`
// (closest point within the set's max_distance; side from the interpolated vertex normal).
std::vector<Contact> find_penetrations(const SimulationMesh& mesh, const Positions& x, double tolerance);

// Contact rows: point minus surface point, pulled to zero with weight
// collision_weight (kPa) * area of the point / target layer thickness.
std::unique_ptr<TargetGroup> contact_group(const SimulationMesh& mesh, const std::vector<Contact>& contacts,
                                           const Eigen::VectorXd& skin_area, double collision_weight);

// Largest distance between the two sides of the contacts at x (m).
double max_contact_gap(const SimulationMesh& mesh, const std::vector<Contact>& contacts, const Positions& x);

// Closest point of triangle (a, b, c) to p as barycentric coordinates (Ericson 2004, 5.1.5).
Eigen::Vector3d closest_point_barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace softdeca::sim
