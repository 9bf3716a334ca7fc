#include "fit/avatar_fit.h"

#include <Eigen/Geometry>
#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <unordered_map>

#include "core/error.h"
#include "fit/mesh_hash.h"
#include "fit/mesh_topology.h"
#include "fit/registration.h"
#include "fit/shape_matcher.h"
#include "geometry/nearest_points.h"
#include "stream/arkit_names.h"

namespace softdeca::fit {
namespace {

using Clock = std::chrono::steady_clock;

// Shapes that move skin and nothing else on every rig: the parts of a mesh they move are its
// skin; eyeballs, teeth and tongue (moved by eyeLook, jaw and tongue shapes) are not.
constexpr const char* kSkinShapes[] = {
    "browDownLeft",    "browDownRight",    "browInnerUp",      "browOuterUpLeft",  "browOuterUpRight",
    "eyeBlinkLeft",    "eyeBlinkRight",    "cheekSquintLeft",  "cheekSquintRight", "noseSneerLeft",
    "noseSneerRight",  "mouthSmileLeft",   "mouthSmileRight",  "mouthDimpleLeft",  "mouthDimpleRight",
    "mouthStretchLeft", "mouthStretchRight", "cheekPuff",
};

// Distances of the embedding (metres): an avatar vertex within kNear of the registered skin
// follows it fully, beyond kFar not at all; the template's face weight falls to zero over
// kFaceFade away from the vertices its shapes move.
constexpr double kNear = 0.003, kFar = 0.010, kFaceFade = 0.03;
// A template vertex takes the avatar's shapes fully within kShapeNear of the avatar's surface,
// its own beyond kShapeFar.
constexpr double kShapeNear = 0.004, kShapeFar = 0.015;
// The identity fit's priors: a shape match's error (2 mm) and a registered vertex's (10 mm,
// squared, metres^2): the registration's errors slide along the skin, coherently.
constexpr double kMatchVariance = 0.002 * 0.002, kRegisteredVariance = 1e-4;
constexpr int kRegistrationRounds = 2;

double smooth_fall(double d, double near, double far) {
  if (d <= near) return 1;
  if (d >= far) return 0;
  const double t = (d - near) / (far - near);
  return 1 - t * t * (3 - 2 * t);
}

Eigen::Vector3d row3(const float* p, std::size_t i) { return {p[3 * i], p[3 * i + 1], p[3 * i + 2]}; }

// Kabsch (Umeyama with `scale`): the rotation (no reflection), scale and translation taking src
// onto dst.
void kabsch(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, Eigen::Matrix3d& r,
            Eigen::Vector3d& t, double* scale = nullptr) {
  Eigen::Vector3d cs = Eigen::Vector3d::Zero(), cd = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < src.size(); ++i) cs += src[i], cd += dst[i];
  cs /= static_cast<double>(src.size());
  cd /= static_cast<double>(src.size());
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < src.size(); ++i) h += (src[i] - cs) * (dst[i] - cd).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  r = svd.matrixV() * d * svd.matrixU().transpose();
  if (scale) {
    double spread = 0;
    for (const Eigen::Vector3d& p : src) spread += (p - cs).squaredNorm();
    *scale = spread > 0 ? (svd.singularValues().asDiagonal() * d).trace() / spread : 1.0;
    r *= *scale;
  }
  t = cd - r * cs;
}

void check_mesh(const AvatarMesh& a) {
  require(a.neutral != nullptr && a.vertex_count >= 3, "the avatar has no vertices");
  require(a.triangles != nullptr && a.triangle_count > 0, "the avatar has no triangles");
  for (std::size_t i = 0; i < 3 * a.vertex_count; ++i)
    if (!std::isfinite(a.neutral[i]))
      throw Error(SOFTDECA_ERROR_NON_FINITE, "the avatar's neutral mesh has a non-finite value at vertex " + std::to_string(i / 3));
  for (std::size_t i = 0; i < 3 * a.triangle_count; ++i)
    require(a.triangles[i] >= 0 && static_cast<std::size_t>(a.triangles[i]) < a.vertex_count,
            "the avatar's triangle " + std::to_string(i / 3) + " has a vertex index outside the mesh");
  for (std::size_t k = 0; k < kShapes; ++k)
    if (a.deltas[k])
      for (std::size_t i = 0; i < 3 * a.vertex_count; ++i)
        if (!std::isfinite(a.deltas[k][i]))
          throw Error(SOFTDECA_ERROR_NON_FINITE, std::string("the avatar's blendshape ") + stream::blendshape_name(k) +
                                                     " has a non-finite value at vertex " + std::to_string(i / 3));
}

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o + "\"";
}

std::string name_list(const std::array<ShapeOrigin, kShapes>& origin, ShapeOrigin which) {
  std::string o = "[";
  for (std::size_t k = 0; k < kShapes; ++k)
    if (origin[k] == which) o += (o.size() > 1 ? ", " : "") + json_string(stream::blendshape_name(k));
  return o + "]";
}

// Where an avatar is: its frame, its unit and the placement into the template's frame.
struct Located {
  AvatarFrame frame;
  double unit = 1;
  bool mirrored = false;
  Placement place;
};

// From the shapes: the frame read off them, then the rigid motion that best takes each shape's
// centre of motion onto the template's. Both hands are tried: the one whose Left and Right
// shapes land on the template's wins (the frame's own guess from the forward shapes or normals
// can be fooled by an unusual rig).
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

// From the bundle's landmarks on an avatar without ARKit shapes: the similarity (either hand)
// that best takes them onto the template's; the face is what lies near the template's face.
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

// The shapes both meshes move, with their deltas in the template's frame.
std::vector<SharedShape> shared_shapes(const TemplateData& t, const AvatarMesh& a, const AvatarFrame& frame,
                                       const AvatarFrame& tframe, const Eigen::Matrix3d& lin) {
  const std::size_t n = a.vertex_count, vs = t.skin_vertices;
  std::vector<SharedShape> shapes;
  for (std::size_t k = 0; k < kShapes; ++k) {
    if (!frame.moves[k] || !tframe.moves[k]) continue;
    SharedShape s;
    s.avatar.resize(static_cast<Eigen::Index>(n), 3);
    for (std::size_t v = 0; v < n; ++v) s.avatar.row(static_cast<Eigen::Index>(v)) = (lin * row3(a.deltas[k], v)).transpose();
    s.template_.resize(static_cast<Eigen::Index>(vs), 3);
    for (std::size_t v = 0; v < vs; ++v) s.template_.row(static_cast<Eigen::Index>(v)) = row3(t.shapes + k * vs * 3, v).transpose();
    shapes.push_back(std::move(s));
  }
  return shapes;
}

// The skin of identity h: the template plus h . modes.
Points identity_points(const TemplateData& t, const std::vector<float>& h) {
  const std::size_t vs = t.skin_vertices;
  Points p(static_cast<Eigen::Index>(vs), 3);
  for (std::size_t v = 0; v < vs; ++v) {
    Eigen::Vector3d x = row3(t.head_neutral, v);
    for (std::size_t k = 0; k < h.size(); ++k) x += static_cast<double>(h[k]) * row3(t.identity_modes + k * vs * 3, v);
    p.row(static_cast<Eigen::Index>(v)) = x.transpose();
  }
  return p;
}

// Identity coefficients whose skin best meets the matches: min sum w |T0 + M h - target|^2 +
// prior |h|^2, the modes scaled so that h is about N(0, 1); `prior`: a match's error, squared
// (metres^2). Reweighted kRobustRounds times (Cauchy, scale kRobustScale): a part the identity
// modes cannot explain (a remesh's cut ears, a stylised nose) does not pull the whole head.
std::vector<float> fit_identity(const TemplateData& t, const std::vector<Match>& matches, const Points& tskin,
                                double prior) {
  constexpr int kRobustRounds = 4;
  constexpr double kRobustScale = 0.001;
  const std::size_t k = t.identity_count, vs = t.skin_vertices;
  const auto kk = static_cast<Eigen::Index>(k);
  std::vector<double> robust(vs, 1.0);
  Eigen::VectorXd h = Eigen::VectorXd::Zero(kk);
  Eigen::MatrixXd rows(3, kk);
  const auto modes_at = [&](std::size_t v) {
    for (std::size_t j = 0; j < k; ++j) rows.col(static_cast<Eigen::Index>(j)) = row3(t.identity_modes + j * vs * 3, v);
  };
  for (int round = 0; round < kRobustRounds; ++round) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Identity(kk, kk) * prior;
    Eigen::VectorXd b = Eigen::VectorXd::Zero(kk);
    for (std::size_t v = 0; v < vs; ++v) {
      const Match& m = matches[v];
      if (!(m.weight > 0)) continue;
      modes_at(v);
      const double w = m.weight * robust[v];
      a.noalias() += w * rows.transpose() * rows;
      b.noalias() += w * rows.transpose() * (m.target - tskin.row(static_cast<Eigen::Index>(v)).transpose());
    }
    h = a.ldlt().solve(b);
    for (std::size_t v = 0; v < vs; ++v) {
      if (!(matches[v].weight > 0)) continue;
      modes_at(v);
      const double r = (rows * h + tskin.row(static_cast<Eigen::Index>(v)).transpose() - matches[v].target).norm();
      robust[v] = 1.0 / (1.0 + (r / kRobustScale) * (r / kRobustScale));
    }
  }
  std::vector<float> out(k);
  for (std::size_t j = 0; j < k; ++j) out[j] = static_cast<float>(h[static_cast<Eigen::Index>(j)]);
  return out;
}

}  // namespace

std::vector<float> identity_skin(const TemplateData& t, const AvatarFit& fit) {
  require(fit.identity.size() == t.identity_count, "the fit's identity does not match the bundle's identity modes");
  const Points p = identity_points(t, fit.identity);
  std::vector<float> out(t.skin_vertices * 3);
  for (std::size_t v = 0; v < t.skin_vertices; ++v)
    for (int c = 0; c < 3; ++c) out[3 * v + static_cast<std::size_t>(c)] = static_cast<float>(p(static_cast<Eigen::Index>(v), c));
  return out;
}

AvatarFit fit_avatar(const TemplateData& t, const AvatarMesh& a, const FitOptions& options) {
  const auto t0 = Clock::now();
  const auto step = [&](const char* what, double share) {
    if (options.progress) options.progress(what, share);
  };
  check_mesh(a);
  require(t.head_neutral && t.shapes && t.skin_triangles && t.skin_vertices > 0, "the bundle has no template head");
  const std::size_t n = a.vertex_count, vs = t.skin_vertices;
  step("reading the avatar's face", 0.0);

  // 1. The face, its axes and unit, on the avatar and (the same way) on the template.
  AvatarShapes ts;
  ts.neutral = t.head_neutral;
  ts.vertex_count = vs;
  ts.triangles = t.skin_triangles;
  ts.triangle_count = t.skin_triangle_count;
  for (std::size_t k = 0; k < kShapes; ++k) ts.deltas[k] = t.moves[k] ? t.shapes + k * vs * 3 : nullptr;
  const AvatarFrame tframe = avatar_frame(ts);
  const bool any_shape = std::any_of(a.deltas.begin(), a.deltas.end(), [](const float* d) { return d != nullptr; });
  const bool by_landmarks = !any_shape && a.landmarks && a.landmark_count == t.landmark_triangle.size();
  require(any_shape || by_landmarks,
          "none of the avatar's ARKit blendshapes moves a vertex: give the rig's ARKit shapes (by name) or the "
          "bundle's landmarks on the avatar");
  // 2. The placement: the avatar's unit and axes to the template's.
  const Located at = by_landmarks ? locate_by_landmarks(t, a, tframe, options.metres_per_unit)
                                   : locate_by_shapes(a, tframe, options.metres_per_unit);
  const AvatarFrame& frame = at.frame;
  const double unit = at.unit;
  const bool mirrored = at.mirrored;
  Placement place = at.place;

  // 3. The avatar's parts and its skin: the parts the skin-only shapes move.
  const MeshTopology topo = mesh_topology(a.neutral, n, a.triangles, a.triangle_count);
  std::vector<uint8_t> skin_part(topo.components, 0);
  for (const char* name : kSkinShapes) {
    const float* d = a.deltas[static_cast<std::size_t>(stream::blendshape_index(name))];
    if (!d) continue;
    double peak = 0;
    for (std::size_t v = 0; v < n; ++v) peak = std::max(peak, row3(d, v).norm());
    for (std::size_t v = 0; v < n; ++v)
      if (peak > 0 && row3(d, v).norm() > 0.05 * peak) skin_part[static_cast<std::size_t>(topo.component[v])] = 1;
  }
  if (std::find(skin_part.begin(), skin_part.end(), 1) == skin_part.end())  // no skin-only shape: every face part
    for (std::size_t v = 0; v < n; ++v)
      if (frame.face[v]) skin_part[static_cast<std::size_t>(topo.component[v])] = 1;
  std::vector<std::int32_t> skin_tris;
  std::vector<uint8_t> skin_edges;
  for (std::size_t f = 0; f < a.triangle_count; ++f) {
    const std::int32_t* c = a.triangles + 3 * f;
    if (!skin_part[static_cast<std::size_t>(topo.component[static_cast<std::size_t>(c[0])])]) continue;
    if (topo.weld[static_cast<std::size_t>(c[0])] == topo.weld[static_cast<std::size_t>(c[1])] ||
        topo.weld[static_cast<std::size_t>(c[1])] == topo.weld[static_cast<std::size_t>(c[2])] ||
        topo.weld[static_cast<std::size_t>(c[0])] == topo.weld[static_cast<std::size_t>(c[2])])
      continue;
    skin_tris.insert(skin_tris.end(), c, c + 3);
    skin_edges.push_back(topo.boundary_edges[f]);
  }
  require(!skin_tris.empty(), "the avatar's face has no triangle with area: nothing to fit to");

  // The avatar in the template's frame.
  Points y(static_cast<Eigen::Index>(n), 3);
  const auto place_all = [&] {
    for (std::size_t v = 0; v < n; ++v) y.row(static_cast<Eigen::Index>(v)) = place.to_template(row3(a.neutral, v)).transpose();
  };
  place_all();

  Points tskin(static_cast<Eigen::Index>(vs), 3);
  for (std::size_t v = 0; v < vs; ++v) tskin.row(static_cast<Eigen::Index>(v)) = row3(t.head_neutral, v).transpose();
  Triangles ttri(static_cast<Eigen::Index>(t.skin_triangle_count), 3);
  for (std::size_t f = 0; f < t.skin_triangle_count * 3; ++f) ttri(static_cast<Eigen::Index>(f / 3), static_cast<Eigen::Index>(f % 3)) = t.skin_triangles[f];
  Triangles atri(static_cast<Eigen::Index>(skin_tris.size() / 3), 3);
  for (std::size_t f = 0; f < skin_tris.size(); ++f) atri(static_cast<Eigen::Index>(f / 3), static_cast<Eigen::Index>(f % 3)) = skin_tris[f];
  std::vector<double> data_weight(vs);
  for (std::size_t v = 0; v < vs; ++v) data_weight[v] = tframe.face[v] ? 1.0 : 0.5;
  std::unique_ptr<ShapeMatcher> matcher;
  const auto match_on_placement = [&] {
    place_all();
    matcher = std::make_unique<ShapeMatcher>(y, atri, skin_edges, topo.boundary_vertex, data_weight,
                                             shared_shapes(t, a, frame, tframe, place.linear));
  };
  match_on_placement();

  // 4. The template identity closest to the avatar, and the placement refined: the template
  // vertices the shapes pin down are matched to the avatar, the rigid motion that best takes the
  // avatar onto them refines the placement, and the identity modes fit to them (a ridge
  // regression: coefficients about N(0, 1), matches good to a couple of millimetres).
  step("finding the closest identity", 0.05);
  Points start = tskin;
  std::vector<float> identity;
  for (const double radius : {0.02, 0.01}) {
    std::vector<Match> m = matcher->shape_matches(start, radius);
    std::vector<Eigen::Vector3d> from, to;
    for (std::size_t i = 0; i < vs; ++i)
      if (m[i].weight > 0) from.push_back(m[i].target), to.push_back(start.row(static_cast<Eigen::Index>(i)).transpose());
    if (from.size() < 10) break;
    Eigen::Matrix3d r;
    Eigen::Vector3d tr;
    kabsch(from, to, r, tr);
    place.linear = r * place.linear;
    place.offset = r * place.offset + tr;
    match_on_placement();
    if (t.identity_count == 0) continue;
    m = matcher->shape_matches(start, radius);
    identity = fit_identity(t, m, tskin, kMatchVariance);
    start = identity_points(t, identity);
  }

  // Guides: the bundle's landmarks on the avatar, when the host gives them.
  std::vector<Guide> guides;
  if (a.landmarks && a.landmark_count == t.landmark_triangle.size())
    for (std::size_t l = 0; l < a.landmark_count; ++l) {
      const auto tri = static_cast<Eigen::Index>(t.landmark_triangle[l]);
      int corner = 0;
      for (int k = 1; k < 3; ++k)
        if (t.landmark_bary[l][static_cast<std::size_t>(k)] > t.landmark_bary[l][static_cast<std::size_t>(corner)]) corner = k;
      guides.push_back({t.skin_triangles[3 * tri + corner], place.to_template(row3(a.landmarks, l)), 2.0});
    }

  // 5. Registration: from the closest identity onto the avatar's skin.
  step("registering the template", 0.1);
  RegistrationSettings settings;
  if (options.iterations > 0) settings.iterations = options.iterations;
  // Twice when the bundle has identity modes: the identity read off the first registration is
  // a closer start for the second.
  const int rounds = t.identity_count ? kRegistrationRounds : 1;
  Registration reg;
  for (int round = 0; round < rounds; ++round) {
    reg = register_skin(start, ttri, std::cref(*matcher), guides, settings, [&](int i, int of) {
      step("registering the template", 0.1 + 0.65 * (round + static_cast<double>(i) / of) / rounds);
    });
    // The identity again, from the registered face: every face vertex placed (measured on
    // held-out ICT identities: a prior this wide reads their codes best).
    if (!t.identity_count) continue;
    std::vector<Match> registered(vs);
    for (std::size_t v = 0; v < vs; ++v)
      if (tframe.face[v]) registered[v] = {reg.skin.row(static_cast<Eigen::Index>(v)).transpose(), 1.0};
    identity = fit_identity(t, registered, tskin, kRegisteredVariance);
    start = identity_points(t, identity);
  }
  const geometry::SurfaceQuery& avatar_surface = matcher->neutral();

  AvatarFit fit;
  fit.mesh_sha256 = mesh_sha256(a.neutral, n, a.triangles, a.triangle_count);
  fit.vertex_count = n;
  fit.triangle_count = a.triangle_count;
  fit.placement = place;
  fit.identity = identity;

  // The registered head: the skin, and every other vertex moved with its nearest skin vertex.
  fit.registered.assign(t.head_neutral, t.head_neutral + t.head_vertices * 3);
  for (std::size_t v = 0; v < vs; ++v)
    for (int c = 0; c < 3; ++c) fit.registered[3 * v + static_cast<std::size_t>(c)] = static_cast<float>(reg.skin(static_cast<Eigen::Index>(v), c));
  if (t.head_vertices > vs) {
    geometry::Sites rest(static_cast<Eigen::Index>(t.head_vertices - vs), 3);
    for (std::size_t v = vs; v < t.head_vertices; ++v) rest.row(static_cast<Eigen::Index>(v - vs)) = row3(t.head_neutral, v).transpose();
    const std::vector<std::int32_t> near = geometry::nearest_sites(tskin, rest);
    for (std::size_t v = vs; v < t.head_vertices; ++v) {
      const auto s = static_cast<Eigen::Index>(near[v - vs]);
      for (int c = 0; c < 3; ++c)
        fit.registered[3 * v + static_cast<std::size_t>(c)] += static_cast<float>(reg.skin(s, c) - tskin(s, c));
    }
  }

  // 6. The residual over the template's face, where the avatar has surface.
  step("measuring the fit", 0.8);
  double sum = 0, worst = 0;
  std::size_t counted = 0;
  for (std::size_t v = 0; v < vs; ++v) {
    if (!tframe.face[v]) continue;
    const geometry::SurfacePoint p = avatar_surface.closest(reg.skin.row(static_cast<Eigen::Index>(v)).transpose(), settings.reach_end * 2);
    if (p.triangle < 0 || matcher->on_boundary(p)) continue;
    const double d = std::sqrt(p.squared_distance);
    sum += d;
    worst = std::max(worst, d);
    ++counted;
  }
  require(counted > 0, "the template's face found no surface of the avatar near it: is this mesh a face?");

  // 7. Where each template vertex reads the avatar's shapes.
  fit.source.corners.assign(vs * 3, 0);
  fit.source.bary.assign(vs * 3, 0.0f);
  fit.source.weight.assign(vs, 0.0f);
  for (std::size_t v = 0; v < vs; ++v) {
    const geometry::SurfacePoint p = avatar_surface.closest(reg.skin.row(static_cast<Eigen::Index>(v)).transpose());
    if (p.triangle < 0) continue;
    for (std::size_t k = 0; k < 3; ++k) {
      fit.source.corners[3 * v + k] = skin_tris[3 * static_cast<std::size_t>(p.triangle) + k];
      fit.source.bary[3 * v + k] = static_cast<float>(p.bary[static_cast<Eigen::Index>(k)]);
    }
    fit.source.weight[v] = static_cast<float>(smooth_fall(std::sqrt(p.squared_distance), kShapeNear, kShapeFar));
  }
  for (std::size_t k = 0; k < kShapes; ++k)
    fit.origin[k] = frame.moves[k] ? ShapeOrigin::Avatar : t.moves[k] ? ShapeOrigin::Template : ShapeOrigin::None;

  // 8. The embedding: every skin-part vertex of the avatar near the registered skin.
  step("embedding the avatar", 0.85);
  std::vector<double> face_weight(vs, 1.0);
  {
    std::vector<Eigen::Index> in_face;
    for (std::size_t v = 0; v < vs; ++v)
      if (tframe.face[v]) in_face.push_back(static_cast<Eigen::Index>(v));
    geometry::Sites sites(static_cast<Eigen::Index>(in_face.size()), 3), queries(static_cast<Eigen::Index>(vs), 3);
    for (std::size_t i = 0; i < in_face.size(); ++i) sites.row(static_cast<Eigen::Index>(i)) = tskin.row(in_face[i]);
    queries = tskin;
    const std::vector<std::int32_t> near = geometry::nearest_sites(sites, queries);
    for (std::size_t v = 0; v < vs; ++v)
      face_weight[v] = smooth_fall((tskin.row(static_cast<Eigen::Index>(v)) - sites.row(near[v])).norm(), 0.0, kFaceFade);
  }
  const geometry::SurfaceQuery registered(reg.skin, ttri);
  const Points tnormals = vertex_normals(reg.skin, ttri);
  for (std::size_t v = 0; v < n; ++v) {
    if (!skin_part[static_cast<std::size_t>(topo.component[v])]) continue;
    const Eigen::Vector3d q = y.row(static_cast<Eigen::Index>(v)).transpose();
    const geometry::SurfacePoint p = registered.closest(q, kFar);
    if (p.triangle < 0) continue;
    double fw = 0;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const auto c = static_cast<std::size_t>(ttri(p.triangle, k));
      fw += p.bary[k] * face_weight[c];
      normal += p.bary[k] * tnormals.row(static_cast<Eigen::Index>(c)).transpose();
    }
    const double w = fw * smooth_fall(std::sqrt(p.squared_distance), kNear, kFar);
    if (!(w > 0)) continue;
    fit.embedding.vertex.push_back(static_cast<std::int32_t>(v));
    fit.embedding.triangle.push_back(p.triangle);
    for (int k = 0; k < 3; ++k) fit.embedding.bary.push_back(static_cast<float>(p.bary[k]));
    fit.embedding.offset.push_back(static_cast<float>((q - p.point).dot(normal.normalized())));
    fit.embedding.weight.push_back(static_cast<float>(w));
  }
  require(!fit.embedding.vertex.empty(), "no vertex of the avatar lies on the registered face");

  // 9. The report.
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  std::size_t full = 0;
  for (const float w : fit.embedding.weight) full += w >= 1.0f;
  std::ostringstream r;
  r.precision(6);
  r << "{\"metres_per_unit\": " << unit << ", \"metres_per_unit_measured\": " << frame.metres_per_unit_measured
    << ", \"up_axis\": " << json_string(frame.up_axis) << ", \"mirrored\": " << (mirrored ? "true" : "false")
    << ", \"vertices\": " << n << ", \"triangles\": " << a.triangle_count << ", \"parts\": " << topo.components
    << ", \"skin_parts\": " << std::count(skin_part.begin(), skin_part.end(), 1)
    << ", \"degenerate_triangles\": " << topo.degenerate_triangles << ", \"face_vertices\": " << frame.face_vertices
    << ", \"embedded_vertices\": " << fit.embedding.size() << ", \"embedded_fully\": " << full
    << ", \"shapes_matched\": " << name_list(fit.origin, ShapeOrigin::Avatar)
    << ", \"shapes_carried\": " << name_list(fit.origin, ShapeOrigin::Template)
    << ", \"shapes_missing\": " << name_list(fit.origin, ShapeOrigin::None) << ", \"landmarks\": " << guides.size() << ", \"matched_by_shapes\": " << matcher->described()
    << ", \"face_residual_mm_mean\": " << 1000 * sum / static_cast<double>(counted)
    << ", \"face_residual_mm_max\": " << 1000 * worst << ", \"face_residual_points\": " << counted
    << ", \"seconds\": " << seconds << "}";
  fit.report = r.str();
  step("done", 1.0);
  return fit;
}

std::vector<float> carried_shapes(const TemplateData& t, const AvatarMesh& a, const AvatarFit& fit) {
  const std::size_t vs = t.skin_vertices, vh = t.head_vertices;
  std::vector<float> out(kShapes * vh * 3, 0.0f);
  const Eigen::Matrix3d& lin = fit.placement.linear;
  for (std::size_t k = 0; k < kShapes; ++k) {
    float* dst = out.data() + k * vh * 3;
    const float* own = t.moves[k] ? t.shapes + k * vs * 3 : nullptr;
    const float* avatar = fit.origin[k] == ShapeOrigin::Avatar ? a.deltas[k] : nullptr;
    for (std::size_t v = 0; v < vs; ++v) {
      Eigen::Vector3d d = own ? row3(own, v) : Eigen::Vector3d::Zero();
      const double w = fit.source.weight[v];
      if (avatar && w > 0) {
        Eigen::Vector3d carried = Eigen::Vector3d::Zero();
        for (std::size_t c = 0; c < 3; ++c)
          carried += fit.source.bary[3 * v + c] * row3(avatar, static_cast<std::size_t>(fit.source.corners[3 * v + c]));
        d = w * (lin * carried) + (1 - w) * d;  // away from the avatar's surface, the template's own
      }
      for (int c = 0; c < 3; ++c) dst[3 * v + static_cast<std::size_t>(c)] = static_cast<float>(d[c]);
    }
  }
  return out;
}

}  // namespace softdeca::fit
