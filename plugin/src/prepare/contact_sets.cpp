#include "prepare/contact_sets.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace softdeca::prepare {

namespace {
using Vec = Eigen::Vector3d;

// The Multi-PIE landmark ids the rules use (plugin/data/contact_rules.json).
constexpr int kInnerLip[] = {SOFTDECA_CONTACT_LANDMARKS_INNER_LIP};
constexpr int kInnerMouthCorners[2] = {SOFTDECA_CONTACT_LANDMARKS_INNER_MOUTH_CORNERS};  // right, left
constexpr int kInnerLipMiddles[2] = {SOFTDECA_CONTACT_LANDMARKS_INNER_LIP_MIDDLES};      // upper, lower
// Per eye (right, left): one corner, the upper lid's two, the other corner, the lower lid's two.
constexpr int kEyes[2][6] = {{SOFTDECA_CONTACT_LANDMARKS_RIGHT_EYE}, {SOFTDECA_CONTACT_LANDMARKS_LEFT_EYE}};

Vec at(const sim::Positions& skin, std::int32_t i) { return skin.row(i).transpose(); }

// Closest point of the polyline to p (the first segment wins a tie).
Vec closest_on_line(const FissureLine& line, const Vec& p) {
  Vec best = line[0];
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k + 1 < line.size(); ++k) {
    const Vec ab = line[k + 1] - line[k];
    const double t = std::clamp((p - line[k]).dot(ab) / ab.dot(ab), 0.0, 1.0);
    const Vec c = line[k] + t * ab;
    const double d = (c - p).norm();
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  return best;
}

// Skin triangles with every corner in `member`.
sim::TriIndices triangles_within(const std::vector<std::int32_t>& tris, const std::vector<char>& member) {
  std::vector<std::int32_t> kept;
  for (std::size_t t = 0; t + 2 < tris.size(); t += 3)
    if (member[static_cast<std::size_t>(tris[t])] && member[static_cast<std::size_t>(tris[t + 1])] &&
        member[static_cast<std::size_t>(tris[t + 2])])
      kept.insert(kept.end(), {tris[t], tris[t + 1], tris[t + 2]});
  return Eigen::Map<const sim::TriIndices>(kept.data(), static_cast<Eigen::Index>(kept.size() / 3), 3);
}
}  // namespace

std::vector<char> lip_contact_zone(const sim::Positions& skin, const std::vector<std::int32_t>& lm, double radius) {
  std::vector<char> zone(static_cast<std::size_t>(skin.rows()), 0);
  for (Eigen::Index i = 0; i < skin.rows(); ++i) {
    const Vec p = at(skin, static_cast<std::int32_t>(i));
    double d = std::numeric_limits<double>::infinity();
    for (const int k : kInnerLip) d = std::min(d, (p - at(skin, lm[static_cast<std::size_t>(k)])).norm());
    zone[static_cast<std::size_t>(i)] = d < radius;
  }
  return zone;
}

// The zone split by the mouth line between the inner corners, raised to the contour's middle;
// points near the corners belong to neither lip.
LipSets lip_sets(const ContactRules& r, const sim::Positions& skin, const std::vector<std::int32_t>& skin_triangles) {
  const auto l = [&](int k) { return at(skin, r.landmarks68[static_cast<std::size_t>(k)]); };
  const std::size_t n = static_cast<std::size_t>(skin.rows());
  const Vec left = l(kInnerMouthCorners[1]), right = l(kInnerMouthCorners[0]);
  const double middle_raise = 0.5 * (l(kInnerLipMiddles[0]).y() + l(kInnerLipMiddles[1]).y()) - 0.5 * (left.y() + right.y());
  const std::vector<char> in_zone = lip_contact_zone(skin, r.landmarks68, r.lip_radius);
  LipSets s;
  std::vector<char> in_upper(n, 0), in_lower(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!in_zone[i]) continue;
    const Vec p = at(skin, static_cast<std::int32_t>(i));
    s.zone.push_back(static_cast<std::int32_t>(i));
    const double t = std::clamp((p.x() - right.x()) / (left.x() - right.x()), 0.0, 1.0);
    const double mouth_y = right.y() + t * (left.y() - right.y()) + middle_raise;
    if (!(std::min((p - right).norm(), (p - left).norm()) > r.lip_corner_radius)) continue;
    (p.y() >= mouth_y ? s.upper : s.lower).push_back(static_cast<std::int32_t>(i));
    (p.y() >= mouth_y ? in_upper : in_lower)[i] = 1;
  }
  s.upper_triangles = triangles_within(skin_triangles, in_upper);
  s.lower_triangles = triangles_within(skin_triangles, in_lower);
  return s;
}

std::array<FissureLine, 2> eye_fissures(const sim::Positions& skin, const std::vector<std::int32_t>& lm) {
  const auto l = [&](int k) { return at(skin, lm[static_cast<std::size_t>(k)]); };
  std::array<FissureLine, 2> lines;
  for (std::size_t e = 0; e < 2; ++e) {
    const int* k = kEyes[e];
    lines[e] = {l(k[0]), 0.5 * (l(k[1]) + l(k[4])), 0.5 * (l(k[2]) + l(k[5])), l(k[3])};
  }
  return lines;
}

// The lids are apart at rest, so the side of the fissure line decides; "up" is +Y without its
// component along the corner-to-corner direction.
std::vector<signed char> lid_sides(const sim::Positions& skin, const std::vector<std::int32_t>& lm,
                                   double eye_zone_share) {
  std::vector<signed char> side(static_cast<std::size_t>(skin.rows()), 0);
  for (const FissureLine& line : eye_fissures(skin, lm)) {
    const Vec middle = 0.5 * (line[1] + line[2]);
    const double width = (line[3] - line[0]).norm();
    const Vec e = (line[3] - line[0]).normalized();
    const Vec up = (Vec::UnitY() - e.y() * e).normalized();
    for (Eigen::Index i = 0; i < skin.rows(); ++i) {
      const Vec p = at(skin, static_cast<std::int32_t>(i));
      if ((p - middle).norm() < eye_zone_share * width)
        side[static_cast<std::size_t>(i)] = (p - closest_on_line(line, p)).dot(up) >= 0 ? 1 : -1;
    }
  }
  return side;
}

// Of the candidates those within lid_reach of a fissure line and farther than
// lid_corner_radius from its corners, by their side.
LidSets lid_sets(const ContactRules& r, const sim::Positions& skin) {
  const std::vector<signed char> side = lid_sides(skin, r.landmarks68, r.eye_zone_share);
  std::vector<char> chosen(static_cast<std::size_t>(skin.rows()), 0);
  for (const FissureLine& line : eye_fissures(skin, r.landmarks68))
    for (const std::int32_t c : r.lid_candidates) {
      const Vec p = at(skin, c);
      const bool near = (p - closest_on_line(line, p)).norm() < r.lid_reach;
      if (near && std::min((p - line[0]).norm(), (p - line[3]).norm()) > r.lid_corner_radius)
        chosen[static_cast<std::size_t>(c)] = 1;
    }
  LidSets s;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    if (chosen[i] && side[i] > 0) s.upper.push_back(static_cast<std::int32_t>(i));
    if (chosen[i] && side[i] < 0) s.lower.push_back(static_cast<std::int32_t>(i));
  }
  return s;
}

std::vector<sim::CollisionSet> contact_sets(const ContactRules& r, const sim::Positions& skin,
                                            const std::vector<std::int32_t>& skin_triangles,
                                            const sim::TriIndices& upper_teeth, const sim::TriIndices& lower_teeth) {
  const LipSets lips = lip_sets(r, skin, skin_triangles);
  const LidSets lids = lid_sets(r, skin);
  std::vector<std::int32_t> lid_points = lids.upper;
  lid_points.insert(lid_points.end(), lids.lower.begin(), lids.lower.end());
  std::vector<sim::CollisionSet> sets(5);
  sets[0] = {"upper_lip_over_lower_lip", lips.upper, lips.lower_triangles, true};
  sets[1] = {"lower_lip_over_upper_lip", lips.lower, lips.upper_triangles, true};
  sets[2] = {"lips_over_upper_teeth", lips.zone, upper_teeth, false};
  sets[3] = {"lips_over_lower_teeth", lips.zone, lower_teeth, false};
  // The eyelids are placed on their targets with no surface to stay out of.
  sets[4] = {"eyelids", lid_points, sim::TriIndices(0, 3), true};
  return sets;
}

}  // namespace softdeca::prepare
