// Lip and teeth collisions (paper 3.3.2), resolved after the volumetric solve by a further
// projective step on the skin surface S itself, as in Komaritzan and Botsch's projective
// skinning: each penetrating point and the closest point of the surface it went through are
// driven by stiff constraints to a common place (their midpoint; the teeth do not move), so
// the two coincide and no gap opens between upper and lower lip; the rest of the lip region
// follows through strain constraints that keep its shape.
//
// Why on S and not through the tets: S rides in the outer tet layer, and where the layer is
// thick (the layered head model closes its wraps over the mouth, so one tet can span both
// lips and the mouth cavity) the embedding cannot move an upper-lip point independently of
// the lower-lip point next to it. On S the resolution is the skin's own.
#pragma once

#include <map>
#include <set>
#include <utility>
#include <vector>

#include "sim/mesh.h"
#include "sim/solver.h"
#include "sim/thread_pool.h"

namespace softdeca::sim {

struct Contact {
  int set;               // index into mesh.collisions
  int32_t point;         // skin point
  int32_t triangle;      // row of the set's surface
  Eigen::Vector3d bary;  // closest point on that triangle
  double depth;          // how far behind the surface (m), positive when penetrating
};

// Adjacency of a collision surface (fixed with the mesh): sorted (edge, triangle) pairs, the
// triangles around each vertex, and the boundary vertices.
struct SurfaceTopology {
  explicit SurfaceTopology(const TriIndices& triangles);
  std::vector<std::pair<std::pair<int32_t, int32_t>, Eigen::Index>> edges;
  std::multimap<int32_t, Eigen::Index> vertex_faces;
  std::set<int32_t> boundary;
};
struct CollisionTopology {
  explicit CollisionTopology(const SimulationMesh& mesh);
  std::vector<SurfaceTopology> sets;  // one per mesh.collisions entry
  Positions rest_skin;                // S at rest: which side of a lip surface a point came from
};

// Points of every collision set that lie behind their surface by more than `tolerance`.
// skin: S's positions; vertices: the simulated vertices (for surfaces on vertices, teeth).
// A point counts when its closest surface point lies within the set's max_distance and
// inside the surface (not on a boundary edge), and the vector to it points against the
// closest feature's pseudo-normal (face, edge or angle-weighted vertex normal: exact
// inside/outside for closed surfaces, Baerentzen and Aanaes 2005). On a surface of S (an open
// lip sheet, where the sign of a far point is not defined and a curled lip's normal flips)
// the point must also have crossed it: at rest it lay on the side the current normal calls
// outside (no more than 3 mm behind), so a point that was always on the far side of a
// rolling lip is no contact.
std::vector<Contact> find_penetrations(const SimulationMesh& mesh, const CollisionTopology& topology,
                                       const Positions& skin, const Positions& vertices, double tolerance);
// The same, building the topology first.
std::vector<Contact> find_penetrations(const SimulationMesh& mesh, const Positions& skin, const Positions& vertices,
                                       double tolerance);

struct CollisionResult {
  Positions skin;  // S after resolution
  int penetrating_before = 0, penetrating_after = 0, contacts = 0, rounds = 0, iterations = 0;
  double max_contact_gap = 0;  // largest distance between the two sides of a contact (m)
  double max_correction = 0;   // largest move of a contact's points by the kept round (m)
  // Rounds stopped because they moved a contact's points farther than the deepest
  // penetration explains, and the largest such move any round made (m).
  int rejected_rounds = 0;
  double largest_round_correction = 0;
  double seconds = 0;
};

// Lip points' targets for the surface step: S_t (or the blended target of eq. 9) and the
// target term's element weights (W / 2, J/m^2) per skin point. The layered head model's
// wraps close over the mouth, so the soft-tissue tets under the lips hold both lips: the
// volumetric solve cannot open a mouth, and the lips are placed on S instead, where they are
// separate surfaces.
struct LipTargets {
  Positions targets;
  Eigen::VectorXd weight;
};

// Detect, tie, solve on S, repeat while a point penetrates or a contact's sides are apart (at
// most settings.collision_rounds times). Contacts persist across rounds, one per (set, point),
// moved to the newest closest point; their targets are fixed per round (collisions.cpp,
// contact_rows). The result is the round with the fewest penetrating points among those that
// reduce them (then the closest contacts) and move no contact's point (nor, on a surface over
// S, its triangle's corners) farther than twice the deepest initial penetration (+ 1 mm);
// otherwise the uncorrected skin. With
// `lips`, the collision sets' points first follow their targets on S (strain relative to the
// targets' shape, the solved skin pinned around the lip region), every frame, and the contacts
// correct that.
CollisionResult resolve_collisions(const SimulationMesh& mesh, const CollisionTopology& topology, const Positions& skin,
                                   const Positions& vertices, const Eigen::VectorXd& skin_area,
                                   const SolverSettings& settings, ThreadPool* pool,
                                   const LipTargets* lips = nullptr);

// Closest point of triangle (a, b, c) to p as barycentric coordinates (Ericson 2004, 5.1.5).
Eigen::Vector3d closest_point_barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace softdeca::sim
