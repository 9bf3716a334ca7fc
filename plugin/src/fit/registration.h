// Non-rigid registration of the template's skin to an avatar (after Amberg et al., "Optimal
// Step Nonrigid ICP", with a displacement-smoothness term instead of per-vertex affinities):
// stiff to soft over the iterations; each iteration asks a matcher for every vertex's target
// (fit/pose_matcher.h) and solves one sparse SPD system for the new skin.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "geometry/surface_query.h"

namespace softdeca::fit {

using geometry::Points;
using geometry::Triangles;

struct Match {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double weight = 0;  // 0: no match this iteration
};

// Fills one match per skin vertex for the current skin, its normals and the iteration's reach
// (metres a match may lie away).
using Matcher = std::function<void(const Points& skin, const Points& normals, double reach, std::vector<Match>& out)>;

struct Guide {
  std::int32_t vertex = 0;  // template skin vertex
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double weight = 1;
};

struct RegistrationSettings {
  int iterations = 12;
  double stiffness_start = 30, stiffness_end = 0.5;  // smoothness weight, geometric schedule
  double reach_start = 0.02, reach_end = 0.004;        // metres a match may lie away
  double guide_weight = 0.5;                           // the guides' weight at the start, fading to a tenth
};

struct Registration {
  Points skin;                   // the registered skin
  std::vector<uint8_t> matched;  // per skin vertex: matched in the last iteration
};

// `progress` (may be empty) gets the iteration done and the count.
Registration register_skin(const Points& start, const Triangles& triangles, const Matcher& matcher,
                           const std::vector<Guide>& guides, const RegistrationSettings& settings,
                           const std::function<void(int, int)>& progress = {});

// Area-weighted unit vertex normals (zero where no incident triangle has area).
Points vertex_normals(const Points& v, const Triangles& f);

}  // namespace softdeca::fit
