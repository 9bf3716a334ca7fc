// Tetrahedral-mesh queries: signed volumes and point embedding (barycentric coordinates).
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

namespace softdeca::geometry {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Tets = Eigen::Matrix<int32_t, Eigen::Dynamic, 4, Eigen::RowMajor>;

// (b-a) . ((c-a) x (d-a)) / 6 for every tet: positive for the layered head model's orientation.
Eigen::VectorXd tet_signed_volumes(const Points& vertices, const Tets& tets);

// Barycentric coordinates of p in tet (a, b, c, d); they sum to one. Degenerate tets give NaN.
Eigen::Vector4d tet_barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                const Eigen::Vector3d& d);

struct Embedding {
  std::vector<int32_t> tet;                                        // per point
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> bary;  // per point, sums to one
  Eigen::VectorXd outside;  // distance to the chosen tet, 0 when the point lies inside
};

// For each point, a tet containing it, or the nearest tet when none does. A uniform grid over
// the tets' bounding boxes keeps this O(points * tets per cell); the fallback widens the search
// ring by ring until the nearest tet is certain.
Embedding embed_points(const Points& vertices, const Tets& tets, const Points& points);

// Distance from p to the closed tet (0 inside).
double point_tet_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d);

}  // namespace softdeca::geometry
