// The collision sets of a head found on its neutral (paper 3.3.2), the one implementation of
// the rules data generation and prepare share (the training package calls it through
// softdeca_native): the lip contact zone around the inner lip contour split into upper and
// lower lip by the mouth line, the lips against the teeth, and the eyelids' points along each
// eye's fissure.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "prepare/contact_rules_table.h"  // generated from plugin/data/contact_rules.json
#include "sim/mesh.h"

namespace softdeca::prepare {

struct ContactRules {
  std::vector<std::int32_t> landmarks68;     // skin vertex indices of the 68 Multi-PIE landmarks
  std::vector<std::int32_t> lid_candidates;  // skin vertices that may belong to a lid
  double lip_radius = SOFTDECA_CONTACT_LIP_RADIUS, lip_corner_radius = SOFTDECA_CONTACT_LIP_CORNER_RADIUS;
  double lid_reach = SOFTDECA_CONTACT_LID_REACH, lid_corner_radius = SOFTDECA_CONTACT_LID_CORNER_RADIUS;
  double eye_zone_share = SOFTDECA_CONTACT_EYE_ZONE_SHARE;
};

// The lips' sets: the zone (both lips, corners too), and of it each lip away from the inner
// mouth corners with the skin triangles whose corners all lie in that lip.
struct LipSets {
  std::vector<std::int32_t> zone, upper, lower;
  sim::TriIndices upper_triangles, lower_triangles;
};

// The lids' points of both eyes.
struct LidSets {
  std::vector<std::int32_t> upper, lower;
};

// An eye's fissure: a polyline from corner to corner through the midpoints of the lids'
// landmark pairs.
using FissureLine = std::array<Eigen::Vector3d, 4>;

// Every function takes landmark and candidate indices inside `skin` (the callers check them:
// prepare/rest_head.cpp, the Python bindings).

// Per skin point: whether it lies within `radius` of the inner lip contour.
std::vector<char> lip_contact_zone(const sim::Positions& skin, const std::vector<std::int32_t>& landmarks68,
                                   double radius);

// `skin_triangles`: S's triangles, 3 indices each.
LipSets lip_sets(const ContactRules& rules, const sim::Positions& skin, const std::vector<std::int32_t>& skin_triangles);

// The fissures of the right eye, then the left.
std::array<FissureLine, 2> eye_fissures(const sim::Positions& skin, const std::vector<std::int32_t>& landmarks68);

// Per skin point: +1 on an upper lid's side of its eye's fissure, -1 on a lower lid's, 0
// farther than `eye_zone_share` of the eye's width from the fissure's middle.
std::vector<signed char> lid_sides(const sim::Positions& skin, const std::vector<std::int32_t>& landmarks68,
                                   double eye_zone_share);

LidSets lid_sets(const ContactRules& rules, const sim::Positions& skin);

// All five sets. upper_teeth / lower_teeth: the teeth's triangles over simulated vertices.
std::vector<sim::CollisionSet> contact_sets(const ContactRules& rules, const sim::Positions& skin,
                                            const std::vector<std::int32_t>& skin_triangles,
                                            const sim::TriIndices& upper_teeth, const sim::TriIndices& lower_teeth);

}  // namespace softdeca::prepare
