#include "fit/fit_quality.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "stream/percentile.h"

namespace softdeca::fit {
namespace {

std::string format(const char* f, double a, double b = 0, double c = 0) {
  char text[256];
  std::snprintf(text, sizeof text, f, a, b, c);
  return text;
}

struct Failure {
  const char* measure;
  std::string what;
};

// Every measure outside its bounds, in the order the verdict names them.
std::vector<Failure> failures(const FitQuality& q, double residual_mm) {
  const QualityBounds& b = kQualityBounds;
  std::vector<Failure> out;
  if (!(q.face_coverage >= b.min_face_coverage))
    out.push_back({"face_coverage", format("the registered template covers %.0f %% of the avatar's face (at least %.0f %% of "
                                           "its face vertices must lie within %.0f mm of it)",
                                           100 * q.face_coverage, 100 * b.min_face_coverage, b.covered_mm)});
  if (!(q.median_mm <= b.max_median_mm))
    out.push_back({"avatar_to_template_mm_median",
                   format("the avatar's face vertices lie a median %.2f mm from the registered template (at most %.1f mm)",
                          q.median_mm, b.max_median_mm)});
  if (!(q.p90_mm <= b.max_p90_mm))
    out.push_back({"avatar_to_template_mm_p90",
                   format("a tenth of the avatar's face vertices lie %.2f mm or more from the registered template (at most "
                          "%.1f mm)",
                          q.p90_mm, b.max_p90_mm)});
  if (!(residual_mm <= b.max_residual_mm))
    out.push_back({"face_residual_mm_mean", format("the registered template's face lies a mean %.2f mm from the avatar's "
                                                   "surface (at most %.1f mm)",
                                                   residual_mm, b.max_residual_mm)});
  if (q.template_scale > 0 && !(q.template_scale >= b.min_template_scale && q.template_scale <= b.max_template_scale))
    out.push_back({"template_scale", format("the registered template's face is %.3f times the size the avatar's shapes give "
                                            "(%.2f to %.2f)",
                                            q.template_scale, b.min_template_scale, b.max_template_scale)});
  return out;
}

// A face's size (FitQuality::template_scale).
double face_size(const QualityInput::Side& side) {
  const std::size_t n = side.centres.size();
  if (n == 0) return 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& c : side.centres) mean += c;
  mean /= static_cast<double>(n);
  double sum = 0;
  for (std::size_t k = 0; k < n; ++k) sum += side.spreads[k] * side.spreads[k] + (side.centres[k] - mean).squaredNorm();
  return std::sqrt(sum / static_cast<double>(n));
}

// What most likely went wrong, from which way the template's size is off.
std::string likely_cause(const FitQuality& q, double metres_per_unit) {
  const QualityBounds& b = kQualityBounds;
  const std::string unit = format("the fit took the mesh's unit as %g m", metres_per_unit);
  if (q.template_scale > 0 && q.template_scale < b.min_template_scale)
    return "the template was squeezed into part of the face: " + unit +
           " (if that is wrong, give the unit), or the rig's shapes do not move the parts of the face their ARKit names "
           "say (check the names)";
  if (q.template_scale > b.max_template_scale)
    return "the template was stretched past the face: " + unit +
           " (if that is wrong, give the unit), or the rig's shapes move more than the face";
  return "the template lies off the face although its size matches: the skin the shapes move has parts the template "
         "cannot lie on (eyelashes, a beard, a separate mask), or the face is far from human proportions";
}

}  // namespace

FitQuality fit_quality(const geometry::SurfaceQuery& registered, const QualityInput& in) {
  FitQuality q;
  std::vector<double> mm;
  mm.reserve(in.avatar_face.size());
  for (const Eigen::Vector3d& p : in.avatar_face) mm.push_back(1000 * std::sqrt(registered.closest(p).squared_distance));
  q.face_points = mm.size();
  if (!mm.empty()) {
    std::size_t covered = 0;
    for (const double d : mm) {
      covered += d <= kQualityBounds.covered_mm;
      q.max_mm = std::max(q.max_mm, d);
    }
    q.face_coverage = static_cast<double>(covered) / static_cast<double>(mm.size());
    q.median_mm = stream::percentile(mm, 0.5);
    q.p90_mm = stream::percentile(mm, 0.9);
  }
  if (in.on_avatar.centres.size() >= 3 && in.on_avatar.centres.size() == in.on_template.centres.size()) {
    const double avatar = face_size(in.on_avatar);
    if (avatar > 0) q.template_scale = face_size(in.on_template) / avatar;
  }
  const std::vector<Failure> failed = failures(q, in.residual_mm);
  if (failed.empty()) return q;
  q.passed = false;
  q.failed_measure = failed.front().measure;
  q.reason = failed.front().what;
  for (std::size_t i = 1; i < failed.size(); ++i) q.reason += (i == 1 ? "; also " : "; ") + failed[i].what;
  q.reason += ". Likely cause: " + likely_cause(q, in.metres_per_unit) + ".";
  return q;
}

}  // namespace softdeca::fit
