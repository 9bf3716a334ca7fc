// The collision sets of a head found on its neutral (paper 3.3.2), by the rules data
// generation uses (training/softdeca_train/sim/lips.py and lids.py): the lip contact zone
// around the inner lip contour split into upper and lower lip by the mouth line, the lips
// against the teeth, and the eyelids' points along each eye's fissure.
#pragma once

#include <cstdint>
#include <vector>

#include "prepare/contact_rules_table.h"  // generated from plugin/data/contact_rules.json
#include "sim/mesh.h"

namespace softdeca::runtime {

struct ContactRules {
  std::vector<std::int32_t> landmarks68;     // skin vertex indices of the 68 Multi-PIE landmarks
  std::vector<std::int32_t> lid_candidates;  // skin vertices that may belong to a lid
  double lip_radius = SOFTDECA_CONTACT_LIP_RADIUS, lip_corner_radius = SOFTDECA_CONTACT_LIP_CORNER_RADIUS;
  double lid_reach = SOFTDECA_CONTACT_LID_REACH, lid_corner_radius = SOFTDECA_CONTACT_LID_CORNER_RADIUS;
  double eye_zone_share = SOFTDECA_CONTACT_EYE_ZONE_SHARE;
};

// upper_teeth / lower_teeth: the teeth's triangles over simulated vertices. `skin_triangles`:
// S's triangles, 3 indices each.
std::vector<sim::CollisionSet> contact_sets(const ContactRules& rules, const sim::Positions& skin,
                                            const std::vector<std::int32_t>& skin_triangles,
                                            const sim::TriIndices& upper_teeth, const sim::TriIndices& lower_teeth);

}  // namespace softdeca::runtime
