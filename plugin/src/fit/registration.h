// Non-rigid registration of the template's skin to an avatar's surface (after Amberg et al.,
// "Optimal Step Nonrigid ICP", with a displacement-smoothness term instead of per-vertex
// affinities): stiff to soft over the iterations, each one closest points on the avatar
// (bounded reach, compatible normals, nothing on the avatar's open boundary) plus guide points
// from the shapes' semantics, solved as one sparse SPD system per iteration.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "geometry/surface_query.h"

namespace softdeca::fit {

using geometry::Points;
using geometry::Triangles;

// The surface registered to, with which of its edges and vertices lie on an open boundary
// (a face mask's rim): closest points there mean "beyond the avatar", not a match.
struct RegistrationTarget {
  const geometry::SurfaceQuery* surface = nullptr;
  std::vector<uint8_t> boundary_edges;   // per triangle: bit k set when the edge opposite corner k is open
  std::vector<uint8_t> boundary_vertex;  // per vertex of the surface
  bool on_boundary(const geometry::SurfacePoint& p) const;
};

struct Guide {
  std::int32_t vertex = 0;  // template skin vertex
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double weight = 1;
};

struct RegistrationSettings {
  int iterations = 24;
  double stiffness_start = 30, stiffness_end = 0.05;  // smoothness weight, geometric schedule
  double reach_start = 0.02, reach_end = 0.004;        // metres a closest point may be away
  double min_normal_cos = 0.5;                         // |cos| between the normals of a match
  double guide_weight = 0.5;                           // the guides' weight at the start, fading to a tenth
};

struct Registration {
  Points skin;                   // the registered skin
  std::vector<uint8_t> matched;  // per skin vertex: matched to the avatar in the last iteration
};

// `data_weight`: per template skin vertex, how much its closest point counts (0: follows the
// others). `progress` (may be empty) gets the iteration done and the count.
Registration register_skin(const Points& start, const Triangles& triangles, const std::vector<double>& data_weight,
                           const RegistrationTarget& target, const std::vector<Guide>& guides,
                           const RegistrationSettings& settings, const std::function<void(int, int)>& progress = {});

// Area-weighted unit vertex normals (zero where no incident triangle has area).
Points vertex_normals(const Points& v, const Triangles& f);

}  // namespace softdeca::fit
