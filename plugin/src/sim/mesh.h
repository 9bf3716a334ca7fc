// The simulation mesh: what the physics model phi† needs to know about a layered head, and
// nothing about how it was built. The layered head model (skin/muscle/skull wraps with prism
// tets, skull, eyes, the embedded skin S) fills it; so do the synthetic meshes of the tests.
//
// Two kinds of points:
//   - simulated vertices (rows of `rest`): every tet and skull vertex, the unknowns;
//   - skin points (S's vertices): each a fixed barycentric combination of up to four
//     simulated vertices (S is embedded in the outer tet layer), so S keeps its resolution
//     whatever the tet resolution. Targets, skin strain, landmarks and lip collisions live
//     on skin points.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace softdeca::sim {

using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using TetIndices = Eigen::Matrix<int32_t, Eigen::Dynamic, 4, Eigen::RowMajor>;
using TriIndices = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Points as fixed combinations sum_k weight(i, k) * x[vertex(i, k)] of simulated vertices.
// Unused slots carry weight 0. A tet embedding (tet, barycentric) maps to the tet's vertices.
struct EmbeddedPoints {
  Eigen::Matrix<int32_t, Eigen::Dynamic, 4, Eigen::RowMajor> vertex;
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> weight;
  Eigen::Index size() const { return vertex.rows(); }
};

// A rigid bone: its vertices follow a rigid transform of their scaled rest positions
// (cranium and jaw scale, Appendix A). Pinned bones are hard constraints, removed from the
// unknowns; a free bone is held only by the skull strain and bending energies (eq. 13).
struct Bone {
  std::vector<int32_t> vertices;
  // Centre of the bone's scaling; NaN: the centroid of its rest vertices.
  Eigen::Vector3d pivot = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool pinned = true;
};

// One side of a collision (paper 3.3.2): skin points that must stay on the outer side of an
// oriented surface (triangle normals, right-hand rule, point to where the points belong).
// Upper against lower lip, lower against upper lip, lips against teeth: one set each.
struct CollisionSet {
  std::string name;
  std::vector<int32_t> points;  // skin point indices
  TriIndices surface;           // over skin points, or over simulated vertices (teeth); empty: the
                                // points are only placed on their targets (the surface step)
  bool surface_on_skin = true;
  double max_distance = 0.01;  // metres: farther closest points are not this contact
};

struct SimulationMesh {
  Positions rest;  // simulated vertices, metres, +Y up, +Z out of the face

  TetIndices soft_tets;        // soft tissue (skin wrap to muscle wrap), positive volume
  TetIndices muscle_tets;      // muscle tissue (muscle wrap to skull wrap), positive volume
  TetIndices connecting_tets;  // skull to muscle, eyes to skull; reoriented when negative
  TriIndices skull_triangles;  // skull surface B over simulated vertices: strain + bending
  Bone cranium, jaw;           // disjoint vertex sets (skull, teeth, eyes ride the cranium)

  EmbeddedPoints skin;       // S: one row per skin point
  TriIndices skin_triangles;  // S's triangles over skin points: skin strain, target areas
  // Area each skin point stands for (targets weigh by it); empty: Voronoi areas of
  // skin_triangles on the rest skin.
  Eigen::VectorXd skin_point_area;

  // SparseSoftDECA landmarks: barycentric points on S (three skin points each).
  Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor> landmark_points;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> landmark_weights;

  std::vector<CollisionSet> collisions;

  Eigen::Index vertex_count() const { return rest.rows(); }
  Eigen::Index skin_count() const { return skin.size(); }
  Eigen::Index landmark_count() const { return landmark_points.rows(); }
};

// Throws Error with the first problem found: sizes, index ranges, non-finite values,
// degenerate or inverted soft/muscle tets, weights that do not sum to one, vertices in no
// element, overlapping bones.
void validate(const SimulationMesh& mesh);

// Skin point positions for simulated vertex positions x.
Positions embed(const EmbeddedPoints& points, const Positions& x);

// Per-point weights of the simulated vertices for landmark l (up to 12 vertices).
struct SparseRow {
  std::vector<int32_t> vertex;
  std::vector<double> weight;
};
SparseRow landmark_row(const SimulationMesh& mesh, Eigen::Index l);

// Tet embedding (tet index, 4 barycentric coordinates per point) to EmbeddedPoints.
EmbeddedPoints embedded_points_from_tets(const TetIndices& tets,
                                         const std::vector<int32_t>& tet_of_point,
                                         const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>& bary);

// Area per skin point: mesh.skin_point_area, or Voronoi areas of the rest skin.
Eigen::VectorXd skin_point_areas(const SimulationMesh& mesh);

}  // namespace softdeca::sim
