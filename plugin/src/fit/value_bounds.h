// The values an avatar mesh may hold, bounded by its own size (docs/security.md, "Avatar
// files"): the import refuses a file that breaks them (naming the file, mesh, shape and
// vertex) and the fit a mesh handed over directly (naming the vertex and shape), by one rule.
//
// - A coordinate within +-kMaxCoordinate units (10,000 km in metres, 10 km in millimetres: any
//   avatar in any unit; beyond, a value that would overflow what is computed from it).
// - A vertex within kStrayReach times the mesh's extent of the box that holds its vertices but
//   the outermost 2 % on each axis (a stray vertex at 1e30 far from a head).
// - A shape's delta no longer than kMaxDeltaReach times the diagonal of the mesh's whole box
//   (a delta of 3e38 would put the animated vertex out of any scene).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

namespace softdeca::fit {

constexpr double kMaxCoordinate = 1e7;
constexpr double kStrayReach = 10;
constexpr double kMaxDeltaReach = 2;

struct MeshExtent {
  Eigen::Vector3d lo, hi;              // the box of the vertices but the outermost 2 % an axis
  Eigen::Vector3d all_lo, all_hi;      // the box of every vertex
  double core_diagonal() const { return (hi - lo).norm(); }
  double diagonal() const { return (all_hi - all_lo).norm(); }
  // How far a vertex may lie from the core box.
  double stray_distance() const { return kStrayReach * core_diagonal(); }
  double max_delta() const { return kMaxDeltaReach * diagonal(); }
};

// `n` xyz vertices (finite).
MeshExtent mesh_extent(const float* vertices, std::size_t n);

// The first vertex beyond kMaxCoordinate or farther than extent.stray_distance() from the core
// box, or -1.
std::int64_t stray_vertex(const float* vertices, std::size_t n, const MeshExtent& extent);

// The first vertex whose delta is longer than extent.max_delta(), or -1.
std::int64_t long_delta(const float* deltas, std::size_t n, const MeshExtent& extent);

}  // namespace softdeca::fit
