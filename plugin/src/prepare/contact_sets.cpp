#include "prepare/contact_sets.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace softdeca::runtime {

namespace {
using Vec = Eigen::Vector3d;
using Line = std::array<Vec, 4>;

Vec at(const sim::Positions& skin, std::int32_t i) { return skin.row(i).transpose(); }

// Closest point of the polyline to p (the first segment wins a tie).
Vec closest_on_line(const Line& line, const Vec& p) {
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

// An eye's fissure: corner, the midpoints of the lids' landmark pairs, the other corner.
Line fissure(const sim::Positions& skin, const std::vector<std::int32_t>& lm, int a, int u0, int w0, int u1, int w1,
             int b) {
  const auto l = [&](int k) { return at(skin, lm[static_cast<std::size_t>(k)]); };
  return {l(a), 0.5 * (l(u0) + l(w0)), 0.5 * (l(u1) + l(w1)), l(b)};
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

std::vector<sim::CollisionSet> contact_sets(const ContactRules& r, const sim::Positions& skin,
                                            const std::vector<std::int32_t>& skin_triangles,
                                            const sim::TriIndices& upper_teeth, const sim::TriIndices& lower_teeth) {
  const std::vector<std::int32_t>& lm = r.landmarks68;
  const auto l = [&](int k) { return at(skin, lm[static_cast<std::size_t>(k)]); };
  const std::size_t n = static_cast<std::size_t>(skin.rows());

  // Lips: the zone within lip_radius of the inner lip contour (landmarks 60-67), split by the
  // mouth line between the inner corners (60, 64) raised to the contour's middle (62, 66).
  const Vec left = l(64), right = l(60);
  const double middle_raise = 0.5 * (l(62).y() + l(66).y()) - 0.5 * (left.y() + right.y());
  std::vector<std::int32_t> zone, upper, lower;
  std::vector<char> in_upper(n, 0), in_lower(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec p = at(skin, static_cast<std::int32_t>(i));
    double d = std::numeric_limits<double>::infinity();
    for (int k = 60; k < 68; ++k) d = std::min(d, (p - l(k)).norm());
    if (!(d < r.lip_radius)) continue;
    zone.push_back(static_cast<std::int32_t>(i));
    const double t = std::clamp((p.x() - right.x()) / (left.x() - right.x()), 0.0, 1.0);
    const double mouth_y = right.y() + t * (left.y() - right.y()) + middle_raise;
    if (!(std::min((p - l(60)).norm(), (p - l(64)).norm()) > r.lip_corner_radius)) continue;
    (p.y() >= mouth_y ? upper : lower).push_back(static_cast<std::int32_t>(i));
    (p.y() >= mouth_y ? in_upper : in_lower)[i] = 1;
  }

  // Lids: per eye, S points on the upper or lower side of its fissure line (within
  // eye_zone_share of the eye's width of its middle), and of the candidates those within
  // lid_reach of the line and farther than lid_corner_radius from its corners.
  const Line eyes[2] = {fissure(skin, lm, 36, 37, 41, 38, 40, 39), fissure(skin, lm, 42, 43, 47, 44, 46, 45)};
  std::vector<signed char> side(n, 0);
  std::vector<char> chosen(n, 0);
  for (const Line& line : eyes) {
    const Vec middle = 0.5 * (line[1] + line[2]);
    const double width = (line[3] - line[0]).norm();
    const Vec e = (line[3] - line[0]).normalized();
    const Vec up = (Vec::UnitY() - e.y() * e).normalized();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec p = at(skin, static_cast<std::int32_t>(i));
      if ((p - middle).norm() < r.eye_zone_share * width) side[i] = (p - closest_on_line(line, p)).dot(up) >= 0 ? 1 : -1;
    }
    for (const std::int32_t c : r.lid_candidates) {
      const Vec p = at(skin, c);
      const bool near = (p - closest_on_line(line, p)).norm() < r.lid_reach;
      if (near && std::min((p - line[0]).norm(), (p - line[3]).norm()) > r.lid_corner_radius)
        chosen[static_cast<std::size_t>(c)] = 1;
    }
  }
  std::vector<std::int32_t> lids_upper, lids_lower;
  for (std::size_t i = 0; i < n; ++i) {
    if (chosen[i] && side[i] > 0) lids_upper.push_back(static_cast<std::int32_t>(i));
    if (chosen[i] && side[i] < 0) lids_lower.push_back(static_cast<std::int32_t>(i));
  }
  std::vector<std::int32_t> lids = lids_upper;
  lids.insert(lids.end(), lids_lower.begin(), lids_lower.end());

  std::vector<sim::CollisionSet> sets(5);
  sets[0] = {"upper_lip_over_lower_lip", upper, triangles_within(skin_triangles, in_lower), true};
  sets[1] = {"lower_lip_over_upper_lip", lower, triangles_within(skin_triangles, in_upper), true};
  sets[2] = {"lips_over_upper_teeth", zone, upper_teeth, false};
  sets[3] = {"lips_over_lower_teeth", zone, lower_teeth, false};
  sets[4] = {"eyelids", lids, sim::TriIndices(0, 3), true};
  return sets;
}

}  // namespace softdeca::runtime
