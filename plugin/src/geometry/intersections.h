// Triangle-mesh intersection tests: the plausibility checks of sampled heads (S must not
// intersect itself) and of the layered head model (wraps must not cut each other or S).
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <utility>
#include <vector>

#include "geometry/cotan.h"

namespace softdeca::geometry {

// True when the closed triangles (a0,a1,a2) and (b0,b1,b2) intersect (non-coplanar case by
// segment-triangle tests; coplanar pairs count as intersecting when they overlap in area).
bool triangles_intersect(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1,
                         const Eigen::Vector3d& a2, const Eigen::Vector3d& b0,
                         const Eigen::Vector3d& b1, const Eigen::Vector3d& b2);

// Pairs (i, j), i < j, of triangles of one mesh that intersect and share no vertex.
std::vector<std::pair<int32_t, int32_t>> self_intersections(const TriPoints& v, const Triangles& f,
                                                            std::size_t max_pairs = 1000);

// Pairs (i in mesh A, j in mesh B) of intersecting triangles of two separate meshes.
std::vector<std::pair<int32_t, int32_t>> mesh_intersections(const TriPoints& va, const Triangles& fa,
                                                            const TriPoints& vb, const Triangles& fb,
                                                            std::size_t max_pairs = 1000);

}  // namespace softdeca::geometry
