// The whole fit of a user's avatar (avatar_fit.h), its steps in the order they run.
// Kept whole: the steps hand each other the mesh's frame, parts and matches; each step is a
// function of its own and its algorithm lives in its own file (registration, placement, ...).
#include "fit/avatar_fit.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "core/error.h"
#include "fit/closest_identity.h"
#include "fit/fit_quality.h"
#include "fit/limits.h"
#include "fit/mesh_hash.h"
#include "fit/mesh_topology.h"
#include "fit/placement.h"
#include "fit/registration.h"
#include "fit/shape_matcher.h"
#include "fit/value_bounds.h"
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
constexpr double kNear = 0.003, kFar = kEmbeddingReach, kFaceFade = 0.03;
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


void check_mesh(const AvatarMesh& a) {
  require(a.neutral != nullptr && a.vertex_count >= 3, "the avatar has no vertices");
  require(a.triangles != nullptr && a.triangle_count > 0, "the avatar has no triangles");
  for (std::size_t i = 0; i < 3 * a.vertex_count; ++i)
    if (!std::isfinite(a.neutral[i]))
      throw Error(SOFTDECA_ERROR_NON_FINITE, "the avatar's neutral mesh has a non-finite value at vertex " + std::to_string(i / 3));
  for (std::size_t i = 0; i < 3 * a.triangle_count; ++i)
    expect(a.triangles[i] >= 0 && static_cast<std::size_t>(a.triangles[i]) < a.vertex_count,
           [&] { return "the avatar's triangle " + std::to_string(i / 3) + " has a vertex index outside the mesh"; });
  for (std::size_t k = 0; k < kShapes; ++k)
    if (a.deltas[k])
      for (std::size_t i = 0; i < 3 * a.vertex_count; ++i)
        if (!std::isfinite(a.deltas[k][i]))
          throw Error(SOFTDECA_ERROR_NON_FINITE, std::string("the avatar's blendshape ") + stream::blendshape_name(k) +
                                                     " has a non-finite value at vertex " + std::to_string(i / 3));
  // Values bounded by the mesh's own size (fit/value_bounds.h).
  const MeshExtent extent = mesh_extent(a.neutral, a.vertex_count);
  const std::int64_t stray = stray_vertex(a.neutral, a.vertex_count, extent);
  expect(stray < 0, [&] {
    return "the avatar's vertex " + std::to_string(stray) + " lies far outside the mesh (more than " +
           std::to_string(static_cast<int>(kStrayReach)) + " times the size of the box its other vertices fill from it): a stray vertex?";
  });
  for (std::size_t k = 0; k < kShapes; ++k) {
    const std::int64_t moved = a.deltas[k] ? long_delta(a.deltas[k], a.vertex_count, extent) : -1;
    expect(moved < 0, [&] {
      return std::string("the avatar's blendshape ") + stream::blendshape_name(k) + " moves vertex " + std::to_string(moved) +
             " by more than " + std::to_string(static_cast<int>(kMaxDeltaReach)) + " times the mesh's size";
    });
  }
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

// The shapes both meshes move: the avatar's deltas (its own coordinates) and the template's.
std::vector<SharedShape> shared_shapes(const TemplateData& t, const AvatarMesh& a, const AvatarFrame& frame,
                                       const AvatarFrame& tframe) {
  const std::size_t vs = t.skin_vertices;
  std::vector<SharedShape> shapes;
  for (std::size_t k = 0; k < kShapes; ++k) {
    if (!frame.moves[k] || !tframe.moves[k]) continue;
    SharedShape s;
    s.avatar = a.deltas[k];
    s.template_.resize(static_cast<Eigen::Index>(vs), 3);
    for (std::size_t v = 0; v < vs; ++v) s.template_.row(static_cast<Eigen::Index>(v)) = row3(t.shapes + k * vs * 3, v).transpose();
    shapes.push_back(std::move(s));
  }
  return shapes;
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

namespace {

// The avatar's skin: the parts the skin-only shapes move (every face part without such a
// shape), their triangles with area and those triangles' open edges.
struct SkinSurface {
  std::vector<uint8_t> part;  // per part of the mesh: skin
  // per vertex: what the skin-only shapes move noticeably (the face the fit's quality is measured
  // on); without such shapes, the frame's face on the skin parts
  std::vector<uint8_t> face;
  std::vector<std::int32_t> triangles;
  std::vector<uint8_t> open_edges;
  std::size_t parts() const { return static_cast<std::size_t>(std::count(part.begin(), part.end(), 1)); }
};

SkinSurface skin_surface(const AvatarMesh& a, const AvatarFrame& frame, const MeshTopology& topo) {
  const std::size_t n = a.vertex_count;
  SkinSurface s;
  s.part.assign(topo.components, 0);
  s.face.assign(n, 0);
  for (const char* name : kSkinShapes) {
    const float* d = a.deltas[static_cast<std::size_t>(stream::blendshape_index(name))];
    if (!d) continue;
    double peak = 0;
    for (std::size_t v = 0; v < n; ++v) peak = std::max(peak, row3(d, v).norm());
    for (std::size_t v = 0; v < n; ++v)
      if (peak > 0 && row3(d, v).norm() > 0.05 * peak) s.part[static_cast<std::size_t>(topo.component[v])] = 1, s.face[v] = 1;
  }
  if (s.parts() == 0)
    for (std::size_t v = 0; v < n; ++v)
      if (frame.face[v]) s.part[static_cast<std::size_t>(topo.component[v])] = 1, s.face[v] = 1;
  const auto weld = [&](std::int32_t v) { return topo.weld[static_cast<std::size_t>(v)]; };
  for (std::size_t f = 0; f < a.triangle_count; ++f) {
    const std::int32_t* c = a.triangles + 3 * f;
    if (!s.part[static_cast<std::size_t>(topo.component[static_cast<std::size_t>(c[0])])]) continue;
    if (weld(c[0]) == weld(c[1]) || weld(c[1]) == weld(c[2]) || weld(c[0]) == weld(c[2])) continue;
    // Corners in a line: a segment, no surface to find a point on.
    if ((row3(a.neutral, std::size_t(c[1])) - row3(a.neutral, std::size_t(c[0])))
            .cross(row3(a.neutral, std::size_t(c[2])) - row3(a.neutral, std::size_t(c[0])))
            .squaredNorm() == 0)
      continue;
    s.triangles.insert(s.triangles.end(), c, c + 3);
    s.open_edges.push_back(topo.boundary_edges[f]);
  }
  require(!s.triangles.empty(), "the avatar's face has no triangle with area: nothing to fit to");
  return s;
}

Triangles triangle_rows(const std::int32_t* indices, std::size_t count) {
  Triangles f(static_cast<Eigen::Index>(count), 3);
  for (std::size_t i = 0; i < count * 3; ++i) f(static_cast<Eigen::Index>(i / 3), static_cast<Eigen::Index>(i % 3)) = indices[i];
  return f;
}

// The avatar's skin is searched (geometry/surface_query.h) with its triangles longer than
// kPieceSize near the template (within kPieceMargin of its box; metres, placed) cut into
// pieces: a face's triangles are shorter, slivers across the mesh are not. The pieces are
// bounded: a face and what lies around it need a few thousand, not kMaxExtraPieces.
constexpr double kPieceSize = 0.01, kPieceMargin = 0.05;
constexpr std::size_t kMaxExtraPieces = 1000000;

geometry::Cutting cutting_near(const Points& template_skin) {
  geometry::Cutting c;
  c.piece_size = kPieceSize;
  c.lo = template_skin.colwise().minCoeff().transpose() - Eigen::Vector3d::Constant(kPieceMargin);
  c.hi = template_skin.colwise().maxCoeff().transpose() + Eigen::Vector3d::Constant(kPieceMargin);
  return c;
}

void require_searchable(const Points& y, const Triangles& f, const geometry::Cutting& cutting) {
  const std::size_t budget = static_cast<std::size_t>(f.rows()) + kMaxExtraPieces;
  if (geometry::SurfaceQuery::entries_needed(y, f, cutting, budget + 1) <= budget) return;
  throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT,
              "the avatar's face has more long triangles than can be searched (their parts of 1 cm would be more than " +
                  std::to_string(kMaxExtraPieces) + "): thin slivers between distant vertices? Remove them");
}

// What the steps of one fit share.
struct Session {
  const TemplateData& t;
  const AvatarMesh& a;
  AvatarFrame tframe;
  Located at;
  MeshTopology topo;
  SkinSurface skin;
  Points y, tskin, start;  // the avatar placed; the template's skin; where the registration starts
  Triangles ttri, atri;
  std::vector<double> data_weight;
  std::unique_ptr<ShapeMatcher> matcher;
  std::vector<float> identity;

  // The avatar in the template's frame on the current placement, and the matcher on it (its
  // long triangles cut, within bounds, at the first).
  void place() {
    y.resize(static_cast<Eigen::Index>(a.vertex_count), 3);
    for (std::size_t v = 0; v < a.vertex_count; ++v)
      y.row(static_cast<Eigen::Index>(v)) = at.place.to_template(row3(a.neutral, v)).transpose();
    const geometry::Cutting cutting = cutting_near(tskin);
    if (!matcher) {
      require_searchable(y, atri, cutting);
      matcher = std::make_unique<ShapeMatcher>(atri, a.vertex_count, skin.open_edges, topo.boundary_vertex, data_weight,
                                               shared_shapes(t, a, at.frame, tframe));
    }
    matcher->place(y, at.place.linear, cutting);
  }
};

// The template identity closest to the avatar, and the placement refined: the template vertices
// the shapes pin down are matched to the avatar, the rigid motion that best takes the avatar
// onto them refines the placement, and the identity modes fit to them (a ridge regression:
// coefficients about N(0, 1), matches good to a couple of millimetres).
void closest_identity(Session& s) {
  const std::size_t vs = s.t.skin_vertices;
  for (const double radius : {0.02, 0.01}) {
    std::vector<Match> m = s.matcher->shape_matches(s.start, radius);
    std::vector<Eigen::Vector3d> from, to;
    for (std::size_t i = 0; i < vs; ++i)
      if (m[i].weight > 0) from.push_back(m[i].target), to.push_back(s.start.row(static_cast<Eigen::Index>(i)).transpose());
    if (from.size() < 10) break;
    Eigen::Matrix3d r;
    Eigen::Vector3d tr;
    kabsch(from, to, r, tr);
    s.at.place.linear = r * s.at.place.linear;
    s.at.place.offset = r * s.at.place.offset + tr;
    s.place();
    if (s.t.identity_count == 0) continue;
    m = s.matcher->shape_matches(s.start, radius);
    s.identity = fit_identity(s.t, m, s.tskin, kMatchVariance);
    s.start = identity_points(s.t, s.identity);
  }
}

// The bundle's landmarks on the avatar, when the host gives them, as guides.
std::vector<Guide> landmark_guides(const Session& s) {
  std::vector<Guide> guides;
  const TemplateData& t = s.t;
  if (!s.a.landmarks || s.a.landmark_count != t.landmark_triangle.size()) return guides;
  for (std::size_t l = 0; l < s.a.landmark_count; ++l) {
    const auto tri = static_cast<std::size_t>(t.landmark_triangle[l]);
    std::size_t corner = 0;
    for (std::size_t k = 1; k < 3; ++k)
      if (t.landmark_bary[l][k] > t.landmark_bary[l][corner]) corner = k;
    guides.push_back({t.skin_triangles[3 * tri + corner], s.at.place.to_template(row3(s.a.landmarks, l)), 2.0});
  }
  return guides;
}

// From the closest identity onto the avatar's skin; twice when the bundle has identity modes:
// the identity read off the first registration (every face vertex placed; measured on held-out
// ICT identities, a prior this wide reads their codes best) is a closer start for the second.
Registration register_rounds(Session& s, const std::vector<Guide>& guides, const RegistrationSettings& settings,
                             const std::function<void(double)>& progress) {
  const std::size_t vs = s.t.skin_vertices;
  const int rounds = s.t.identity_count ? kRegistrationRounds : 1;
  Registration reg;
  for (int round = 0; round < rounds; ++round) {
    reg = register_skin(s.start, s.ttri, std::cref(*s.matcher), guides, settings,
                        [&](int i, int of) { progress((round + static_cast<double>(i) / of) / rounds); });
    if (!s.t.identity_count) continue;
    std::vector<Match> registered(vs);
    for (std::size_t v = 0; v < vs; ++v)
      if (s.tframe.face[v]) registered[v] = {reg.skin.row(static_cast<Eigen::Index>(v)).transpose(), 1.0};
    s.identity = fit_identity(s.t, registered, s.tskin, kRegisteredVariance);
    s.start = identity_points(s.t, s.identity);
  }
  return reg;
}

// The registered head: the skin, and every other vertex moved with its nearest skin vertex.
std::vector<float> registered_head(const Session& s, const Points& skin) {
  const TemplateData& t = s.t;
  const std::size_t vs = t.skin_vertices;
  std::vector<float> head(t.head_neutral, t.head_neutral + t.head_vertices * 3);
  for (std::size_t v = 0; v < vs; ++v)
    for (int c = 0; c < 3; ++c) head[3 * v + static_cast<std::size_t>(c)] = static_cast<float>(skin(static_cast<Eigen::Index>(v), c));
  if (t.head_vertices == vs) return head;
  geometry::Sites rest(static_cast<Eigen::Index>(t.head_vertices - vs), 3);
  for (std::size_t v = vs; v < t.head_vertices; ++v) rest.row(static_cast<Eigen::Index>(v - vs)) = row3(t.head_neutral, v).transpose();
  const std::vector<std::int32_t> near = geometry::nearest_sites(s.tskin, rest);
  for (std::size_t v = vs; v < t.head_vertices; ++v) {
    const auto n = static_cast<Eigen::Index>(near[v - vs]);
    for (int c = 0; c < 3; ++c) head[3 * v + static_cast<std::size_t>(c)] += static_cast<float>(skin(n, c) - s.tskin(n, c));
  }
  return head;
}

struct Residual {
  double mean_mm = 0, max_mm = 0;
  std::size_t points = 0, beyond_rim = 0;
  std::vector<uint8_t> past_rim;  // per template skin vertex: on the face, past the avatar's rim
};

// The registered template's distance to the avatar's surface over the template's face, however
// far; the template's vertices whose closest point is on the avatar's open rim (past a face
// mask's edge, where the avatar has no surface) are counted apart.
Residual face_residual(const Session& s, const Points& skin) {
  Residual r;
  r.past_rim.assign(s.t.skin_vertices, 0);
  double sum = 0;
  for (std::size_t v = 0; v < s.t.skin_vertices; ++v) {
    if (!s.tframe.face[v]) continue;
    const geometry::SurfacePoint p = s.matcher->neutral().closest(skin.row(static_cast<Eigen::Index>(v)).transpose());
    if (s.matcher->on_boundary(p)) {
      ++r.beyond_rim;
      r.past_rim[v] = 1;
      continue;
    }
    const double d = 1000 * std::sqrt(p.squared_distance);
    sum += d;
    r.max_mm = std::max(r.max_mm, d);
    ++r.points;
  }
  require(r.points > 0, "every point of the template's face lies past the avatar's open rim: is this mesh a face?");
  r.mean_mm = sum / static_cast<double>(r.points);
  return r;
}

// What the fit's quality is measured on (fit/fit_quality.h): the avatar's face vertices, placed,
// and what each side's face size is read off: the skin-only shapes both move, on the avatar
// (its frame's, placed; spreads in metres) and on the registered template (its own shapes over
// the registered skin `registered`, where the avatar has surface: past a face mask's rim the
// template has face the avatar lacks); for a fit by landmarks, the landmarks.
QualityInput quality_input(const Session& s, const std::vector<float>& registered, const Residual& residual) {
  QualityInput in;
  in.metres_per_unit = s.at.unit;
  in.residual_mm = residual.mean_mm;
  for (std::size_t v = 0; v < s.a.vertex_count; ++v)
    if (s.skin.face[v]) in.avatar_face.push_back(s.y.row(static_cast<Eigen::Index>(v)).transpose());
  const TemplateData& t = s.t;
  const std::size_t vs = t.skin_vertices;
  AvatarShapes shapes;
  shapes.neutral = registered.data();  // its first skin_vertices rows: the registered skin
  shapes.vertex_count = vs;
  shapes.triangles = t.skin_triangles;
  shapes.triangle_count = t.skin_triangle_count;
  std::vector<float> covered(std::size(kSkinShapes) * vs * 3, 0.0f);  // the skin-only shapes where the avatar has surface
  for (std::size_t i = 0; i < std::size(kSkinShapes); ++i) {
    const auto k = static_cast<std::size_t>(stream::blendshape_index(kSkinShapes[i]));
    if (!t.moves[k]) continue;
    float* d = covered.data() + i * vs * 3;
    for (std::size_t v = 0; v < 3 * vs; ++v)
      if (!residual.past_rim[v / 3]) d[v] = t.shapes[k * vs * 3 + v];
    shapes.deltas[k] = d;
  }
  const ShapeCentres on_template = shape_centres(shapes);
  const AvatarFrame& frame = s.at.frame;
  for (const char* name : kSkinShapes) {
    const auto k = static_cast<std::size_t>(stream::blendshape_index(name));
    if (!frame.moves[k] || !on_template.moves[k]) continue;
    in.on_avatar.centres.push_back(s.at.place.to_template(frame.centres[k]));
    in.on_avatar.spreads.push_back(s.at.unit * frame.spreads[k]);
    in.on_template.centres.push_back(on_template.centres[k]);
    in.on_template.spreads.push_back(on_template.spreads[k]);
  }
  if (in.on_avatar.centres.size() >= 3 || !s.a.landmarks || s.a.landmark_count != t.landmark_triangle.size()) return in;
  in.on_avatar = in.on_template = {};
  for (std::size_t l = 0; l < s.a.landmark_count; ++l) {
    in.on_avatar.centres.push_back(s.at.place.to_template(row3(s.a.landmarks, l)));
    const auto tri = static_cast<std::size_t>(t.landmark_triangle[l]);
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k)
      p += t.landmark_bary[l][k] * row3(registered.data(), static_cast<std::size_t>(t.skin_triangles[3 * tri + k]));
    in.on_template.centres.push_back(p);
  }
  in.on_avatar.spreads.assign(s.a.landmark_count, 0.0);
  in.on_template.spreads.assign(s.a.landmark_count, 0.0);
  return in;
}

// Where each template vertex reads the avatar's shapes: its closest point of the avatar's skin.
ShapeSource shape_source(const Session& s, const Points& skin) {
  const std::size_t vs = s.t.skin_vertices;
  ShapeSource src;
  src.corners.assign(vs * 3, 0);
  src.bary.assign(vs * 3, 0.0f);
  src.weight.assign(vs, 0.0f);
  for (std::size_t v = 0; v < vs; ++v) {
    // Beyond kShapeFar the template's own shape is used: no need to look farther.
    const geometry::SurfacePoint p = s.matcher->neutral().closest(skin.row(static_cast<Eigen::Index>(v)).transpose(), kShapeFar);
    if (p.triangle < 0) continue;
    for (std::size_t k = 0; k < 3; ++k) {
      src.corners[3 * v + k] = s.skin.triangles[3 * static_cast<std::size_t>(p.triangle) + k];
      src.bary[3 * v + k] = static_cast<float>(p.bary[static_cast<Eigen::Index>(k)]);
    }
    src.weight[v] = static_cast<float>(smooth_fall(std::sqrt(p.squared_distance), kShapeNear, kShapeFar));
  }
  return src;
}

// Every skin-part vertex of the avatar near the registered skin, weighted 1 on the template's
// face and fading over kFaceFade beyond it and from kNear to kFar away from the skin.
Embedding embed(const Session& s, const geometry::SurfaceQuery& registered) {
  const Points& skin = registered.vertices();
  const std::size_t vs = s.t.skin_vertices;
  std::vector<Eigen::Index> in_face;
  for (std::size_t v = 0; v < vs; ++v)
    if (s.tframe.face[v]) in_face.push_back(static_cast<Eigen::Index>(v));
  geometry::Sites sites(static_cast<Eigen::Index>(in_face.size()), 3);
  for (std::size_t i = 0; i < in_face.size(); ++i) sites.row(static_cast<Eigen::Index>(i)) = s.tskin.row(in_face[i]);
  const std::vector<std::int32_t> near = geometry::nearest_sites(sites, s.tskin);
  std::vector<double> face_weight(vs);
  for (std::size_t v = 0; v < vs; ++v)
    face_weight[v] = smooth_fall((s.tskin.row(static_cast<Eigen::Index>(v)) - sites.row(near[v])).norm(), 0.0, kFaceFade);
  const Points normals = vertex_normals(skin, s.ttri);
  Embedding e;
  for (std::size_t v = 0; v < s.a.vertex_count; ++v) {
    if (!s.skin.part[static_cast<std::size_t>(s.topo.component[v])]) continue;
    const Eigen::Vector3d q = s.y.row(static_cast<Eigen::Index>(v)).transpose();
    const geometry::SurfacePoint p = registered.closest(q, kFar);
    if (p.triangle < 0) continue;
    double fw = 0;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const auto c = static_cast<std::size_t>(s.ttri(p.triangle, k));
      fw += p.bary[k] * face_weight[c];
      normal += p.bary[k] * normals.row(static_cast<Eigen::Index>(c)).transpose();
    }
    const double w = fw * smooth_fall(std::sqrt(p.squared_distance), kNear, kFar);
    if (!(w > 0)) continue;
    e.vertex.push_back(static_cast<std::int32_t>(v));
    e.triangle.push_back(p.triangle);
    for (int k = 0; k < 3; ++k) e.bary.push_back(static_cast<float>(p.bary[k]));
    e.offset.push_back(static_cast<float>((q - p.point).dot(normal.normalized())));
    e.weight.push_back(static_cast<float>(w));
  }
  require(!e.vertex.empty(), "no vertex of the avatar lies on the registered face");
  return e;
}

// The verdict and the bounds it was judged by (fit/fit_quality.h).
std::string quality_json(const FitQuality& q) {
  const QualityBounds& b = kQualityBounds;
  std::ostringstream o;
  o << "{\"passed\": " << (q.passed ? "true" : "false") << ", \"failed_measure\": " << json_string(q.failed_measure)
    << ", \"reason\": " << json_string(q.reason) << ", \"bounds\": {\"covered_mm\": " << b.covered_mm
    << ", \"face_coverage_min\": " << b.min_face_coverage << ", \"avatar_to_template_mm_median_max\": " << b.max_median_mm
    << ", \"avatar_to_template_mm_p90_max\": " << b.max_p90_mm << ", \"face_residual_mm_mean_max\": " << b.max_residual_mm
    << ", \"template_scale_min\": " << b.min_template_scale
    << ", \"template_scale_max\": " << b.max_template_scale << "}}";
  return o.str();
}

std::string report_json(const Session& s, const AvatarFit& fit, const Residual& r, const FitQuality& q, std::size_t landmarks,
                        double seconds) {
  const AvatarFrame& frame = s.at.frame;
  std::size_t full = 0;
  for (const float w : fit.embedding.weight) full += w >= 1.0f;
  std::ostringstream o;
  o.precision(6);
  o << "{\"metres_per_unit\": " << s.at.unit << ", \"metres_per_unit_measured\": " << frame.metres_per_unit_measured
    << ", \"up_axis\": " << json_string(frame.up_axis) << ", \"mirrored\": " << (s.at.mirrored ? "true" : "false")
    << ", \"vertices\": " << s.a.vertex_count << ", \"triangles\": " << s.a.triangle_count << ", \"parts\": " << s.topo.components
    << ", \"skin_parts\": " << s.skin.parts() << ", \"degenerate_triangles\": " << s.topo.degenerate_triangles
    << ", \"face_vertices\": " << frame.face_vertices << ", \"embedded_vertices\": " << fit.embedding.size()
    << ", \"embedded_fully\": " << full << ", \"shapes_matched\": " << name_list(fit.origin, ShapeOrigin::Avatar)
    << ", \"shapes_carried\": " << name_list(fit.origin, ShapeOrigin::Template)
    << ", \"shapes_missing\": " << name_list(fit.origin, ShapeOrigin::None) << ", \"landmarks\": " << landmarks
    << ", \"matched_by_shapes\": " << s.matcher->described() << ", \"face_residual_mm_mean\": " << r.mean_mm
    << ", \"face_residual_mm_max\": " << r.max_mm << ", \"face_residual_points\": " << r.points
    << ", \"face_residual_beyond_rim\": " << r.beyond_rim << ", \"face_coverage\": " << q.face_coverage
    << ", \"face_coverage_vertices\": " << q.face_points << ", \"avatar_to_template_mm_median\": " << q.median_mm
    << ", \"avatar_to_template_mm_p90\": " << q.p90_mm << ", \"avatar_to_template_mm_max\": " << q.max_mm
    << ", \"template_scale\": ";
  if (q.template_scale > 0) o << q.template_scale;
  else o << "null";
  o << ", \"quality\": " << quality_json(q) << ", \"seconds\": " << seconds << "}";
  return o.str();
}

}  // namespace

AvatarFit fit_avatar(const TemplateData& t, const AvatarMesh& a, const FitOptions& options) {
  const auto t0 = Clock::now();
  const auto step = [&](const char* what, double share) {
    if (options.progress) options.progress(what, share);
  };
  check_mesh(a);
  require(t.head_neutral && t.shapes && t.skin_triangles && t.skin_vertices > 0, "the bundle has no template head");
  const std::size_t vs = t.skin_vertices;
  step("reading the avatar's face", 0.0);

  // The face, its axes and unit, on the avatar and (the same way) on the template, and the
  // placement: from the shapes, or from the bundle's landmarks on an avatar without shapes.
  AvatarShapes ts;
  ts.neutral = t.head_neutral;
  ts.vertex_count = vs;
  ts.triangles = t.skin_triangles;
  ts.triangle_count = t.skin_triangle_count;
  for (std::size_t k = 0; k < kShapes; ++k) ts.deltas[k] = t.moves[k] ? t.shapes + k * vs * 3 : nullptr;
  Session s{t, a, avatar_frame(ts), {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}};
  const bool any_shape = std::any_of(a.deltas.begin(), a.deltas.end(), [](const float* d) { return d != nullptr; });
  const bool by_landmarks = !any_shape && a.landmarks && a.landmark_count == t.landmark_triangle.size();
  require(any_shape || by_landmarks,
          "none of the avatar's ARKit blendshapes moves a vertex: give the rig's ARKit shapes (by name) or the "
          "bundle's landmarks on the avatar");
  s.at = by_landmarks ? locate_by_landmarks(t, a, s.tframe, options.metres_per_unit)
                      : locate_by_shapes(a, s.tframe, options.metres_per_unit);
  s.topo = mesh_topology(a.neutral, a.vertex_count, a.triangles, a.triangle_count);
  s.skin = skin_surface(a, s.at.frame, s.topo);
  s.tskin.resize(static_cast<Eigen::Index>(vs), 3);
  for (std::size_t v = 0; v < vs; ++v) s.tskin.row(static_cast<Eigen::Index>(v)) = row3(t.head_neutral, v).transpose();
  s.start = s.tskin;
  s.ttri = triangle_rows(t.skin_triangles, t.skin_triangle_count);
  s.atri = triangle_rows(s.skin.triangles.data(), s.skin.triangles.size() / 3);
  s.data_weight.resize(vs);
  for (std::size_t v = 0; v < vs; ++v) s.data_weight[v] = s.tframe.face[v] ? 1.0 : 0.5;
  s.place();

  step("finding the closest identity", 0.05);
  closest_identity(s);
  const std::vector<Guide> guides = landmark_guides(s);
  step("registering the template", 0.1);
  RegistrationSettings settings;
  if (options.iterations > 0) settings.iterations = options.iterations;
  const Registration reg = register_rounds(s, guides, settings, [&](double share) { step("registering the template", 0.1 + 0.65 * share); });
  if (t.identity_count) {
    step("reading the identity", 0.75);
    s.identity = refine_identity(
        t, s.matcher->neutral(), [&](const geometry::SurfacePoint& p) { return s.matcher->on_boundary(p); }, s.identity);
  }

  AvatarFit fit;
  fit.mesh_sha256 = mesh_sha256(a.neutral, a.vertex_count, a.triangles, a.triangle_count);
  fit.vertex_count = a.vertex_count;
  fit.triangle_count = a.triangle_count;
  fit.placement = s.at.place;
  fit.identity = s.identity;
  fit.registered = registered_head(s, reg.skin);
  step("measuring the fit", 0.8);
  const Residual residual = face_residual(s, reg.skin);
  const geometry::SurfaceQuery registered(reg.skin, s.ttri);
  const FitQuality quality = fit_quality(registered, quality_input(s, fit.registered, residual));
  fit.source = shape_source(s, reg.skin);
  for (std::size_t k = 0; k < kShapes; ++k)
    fit.origin[k] = s.at.frame.moves[k] ? ShapeOrigin::Avatar : t.moves[k] ? ShapeOrigin::Template : ShapeOrigin::None;
  step("embedding the avatar", 0.85);
  fit.embedding = embed(s, registered);
  fit.report =
      report_json(s, fit, residual, quality, guides.size(), std::chrono::duration<double>(Clock::now() - t0).count());
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
