#include "fit/placement.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "geometry/nearest_points.h"
#include "geometry/rigid.h"

namespace softdeca::fit {

void kabsch(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, Eigen::Matrix3d& r,
            Eigen::Vector3d& t, double* scale) {
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "the vectors are read as xyz-interleaved arrays");
  const geometry::Similarity s = geometry::fit_similarity(src.front().data(), dst.front().data(), src.size(), scale != nullptr);
  r = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(s.rotation) * s.scale;
  t = Eigen::Map<const Eigen::Vector3d>(s.translation);
  if (scale) *scale = s.scale;
}

Located locate_by_shapes(const AvatarMesh& a, const AvatarFrame& tframe, double unit_option) {
  AvatarShapes as;
  as.neutral = a.neutral;
  as.vertex_count = a.vertex_count;
  as.deltas = a.deltas;
  as.triangles = a.triangles;
  as.triangle_count = a.triangle_count;
  Located at;
  at.frame = avatar_frame(as);
  const AvatarFrame& frame = at.frame;
  at.unit = unit_option > 0 ? unit_option : frame.metres_per_unit;
  Eigen::Matrix3d axes;
  axes.row(0) = frame.left.transpose();
  axes.row(1) = frame.up.transpose();
  axes.row(2) = frame.forward.transpose();
  std::vector<std::size_t> shared;
  for (std::size_t k = 0; k < kShapes; ++k)
    if (frame.moves[k] && tframe.moves[k]) shared.push_back(k);
  require(shared.size() >= 3, "the avatar shares fewer than 3 moving ARKit shapes with the template: too few to place it");
  double best = std::numeric_limits<double>::infinity();
  for (const double hand : {1.0, -1.0}) {
    Eigen::Matrix3d linear = at.unit * axes;
    linear.row(2) *= hand;
    std::vector<Eigen::Vector3d> src, dst;
    for (const std::size_t k : shared) {
      src.push_back(linear * frame.centres[k]);
      dst.push_back(tframe.centres[k]);
    }
    Eigen::Matrix3d r;
    Eigen::Vector3d tr;
    kabsch(src, dst, r, tr);
    double rms = 0;
    for (std::size_t i = 0; i < src.size(); ++i) rms += (r * src[i] + tr - dst[i]).squaredNorm();
    if (rms < best) {
      best = rms;
      at.place.linear = r * linear;
      at.place.offset = tr;
      at.mirrored = hand < 0 ? !frame.mirrored : frame.mirrored;
    }
  }
  return at;
}

Located locate_by_landmarks(const TemplateData& t, const AvatarMesh& a, const AvatarFrame& tframe, double unit_option) {
  constexpr double kFaceReach = 0.015;  // metres from the template's face that count as the avatar's face
  std::vector<Eigen::Vector3d> src, dst;
  for (std::size_t l = 0; l < a.landmark_count; ++l) {
    src.push_back(row3(a.landmarks, l));
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k)
      p += t.landmark_bary[l][k] *
           row3(t.head_neutral, static_cast<std::size_t>(t.skin_triangles[3 * static_cast<std::size_t>(t.landmark_triangle[l]) + k]));
    dst.push_back(p);
  }
  Located at;
  double best = std::numeric_limits<double>::infinity();
  for (const double hand : {1.0, -1.0}) {
    const Eigen::Matrix3d flip = Eigen::Vector3d(1, 1, hand).asDiagonal();
    std::vector<Eigen::Vector3d> flipped;
    for (const Eigen::Vector3d& p : src) flipped.push_back(flip * p);
    Eigen::Matrix3d r;
    Eigen::Vector3d tr;
    double scale = 1;
    kabsch(flipped, dst, r, tr, &scale);
    double rms = 0;
    for (std::size_t i = 0; i < src.size(); ++i) rms += (r * flipped[i] + tr - dst[i]).squaredNorm();
    if (!(rms < best) || !(scale > 0)) continue;
    best = rms;
    at.frame.metres_per_unit_measured = scale;
    at.unit = unit_option > 0 ? unit_option : snap_unit(scale);
    at.mirrored = hand < 0;
    const Eigen::Matrix3d axes = r / scale * flip;  // avatar directions to the template's
    at.place.linear = at.unit * axes;
    Eigen::Vector3d cs = Eigen::Vector3d::Zero(), cd = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < src.size(); ++i) cs += src[i], cd += dst[i];
    at.place.offset = (cd - at.place.linear * cs) / static_cast<double>(src.size());
    at.frame.left = axes.row(0).transpose();
    at.frame.up = axes.row(1).transpose();
    at.frame.forward = axes.row(2).transpose();
  }
  require(std::isfinite(best), "the landmarks give no placement: are they the bundle's, in its order?");
  at.frame.metres_per_unit = at.unit;
  at.frame.up_axis = axis_name(at.frame.up);
  at.frame.mirrored = at.mirrored;
  // The face: the avatar's vertices near the template's face once placed.
  std::vector<Eigen::Index> face;
  for (std::size_t v = 0; v < t.skin_vertices; ++v)
    if (tframe.face[v]) face.push_back(static_cast<Eigen::Index>(v));
  geometry::Sites sites(static_cast<Eigen::Index>(face.size()), 3), placed(static_cast<Eigen::Index>(a.vertex_count), 3);
  for (std::size_t i = 0; i < face.size(); ++i) sites.row(static_cast<Eigen::Index>(i)) = row3(t.head_neutral, static_cast<std::size_t>(face[i])).transpose();
  for (std::size_t v = 0; v < a.vertex_count; ++v) placed.row(static_cast<Eigen::Index>(v)) = at.place.to_template(row3(a.neutral, v)).transpose();
  const std::vector<std::int32_t> near = geometry::nearest_sites(sites, placed);
  at.frame.face.assign(a.vertex_count, 0);
  for (std::size_t v = 0; v < a.vertex_count; ++v)
    if ((placed.row(static_cast<Eigen::Index>(v)) - sites.row(near[v])).norm() < kFaceReach) at.frame.face[v] = 1, ++at.frame.face_vertices;
  require(at.frame.face_vertices > 0, "no vertex of the avatar lies near the template's face at its landmarks");
  return at;
}

}  // namespace softdeca::fit
