#include "sim/collisions.h"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <algorithm>
#include <map>

#include "sim/constraints_surface.h"
#include "sim/constraints_target.h"
#include "sim/model.h"
#include "sim/system.h"

namespace softdeca::sim {
namespace {
using Vec3 = Eigen::Vector3d;

std::pair<int32_t, int32_t> edge_key(int32_t a, int32_t b) { return a < b ? std::make_pair(a, b) : std::make_pair(b, a); }

// Pseudo-normal of the closest feature (face; edge: sum of its faces' normals; vertex:
// angle-weighted normal) from the surface's topology and the current positions; false on the
// boundary, where inside and outside are undefined.
bool feature_normal(const SurfaceTopology& topo, const TriIndices& tris, const Positions& x, Eigen::Index t,
                    const Vec3& b, Vec3& n) {
  auto face_normal = [&](Eigen::Index f) {
    const Vec3 p0 = x.row(tris(f, 0)), p1 = x.row(tris(f, 1)), p2 = x.row(tris(f, 2));
    const Vec3 m = (p1 - p0).cross(p2 - p0);
    return m.norm() > 0 ? Vec3(m.normalized()) : Vec3::Zero();
  };
  int nonzero[3], count = 0;
  for (int k = 0; k < 3; ++k)
    if (b[k] > 0) nonzero[count++] = k;
  if (count == 3) {
    n = face_normal(t);
    return true;
  }
  if (count == 2) {
    const auto key = edge_key(tris(t, nonzero[0]), tris(t, nonzero[1]));
    const auto range = std::equal_range(topo.edges.begin(), topo.edges.end(), std::make_pair(key, Eigen::Index{-1}),
                                        [](const auto& l, const auto& r) { return l.first < r.first; });
    if (range.second - range.first < 2) return false;
    n.setZero();
    for (auto it = range.first; it != range.second; ++it) n += face_normal(it->second);
    return true;
  }
  const int32_t v = tris(t, nonzero[0]);
  if (topo.boundary.count(v)) return false;
  n.setZero();
  const auto range = topo.vertex_faces.equal_range(v);
  for (auto it = range.first; it != range.second; ++it) {
    const Eigen::Index f = it->second;
    int k = 0;
    while (tris(f, k) != v) ++k;
    const Vec3 p = x.row(v), e1 = Vec3(x.row(tris(f, (k + 1) % 3))) - p, e2 = Vec3(x.row(tris(f, (k + 2) % 3))) - p;
    n += std::atan2(e1.cross(e2).norm(), e1.dot(e2)) * face_normal(f);
  }
  return true;
}

const Positions& surface_positions(const CollisionSet& set, const Positions& skin, const Positions& vertices) {
  return set.surface_on_skin ? skin : vertices;
}

// The contact's constraint rows over S (unknowns of the surface step), each with a fixed
// target, appended to `rows` / `targets`. Against a surface on simulated vertices (teeth,
// fixed in this step) the point's target is its closest surface point. Against a surface on
// S both sides move halfway: the point to the midpoint of it and its closest surface point,
// the surface triangle's corners by the same translation (rows weighted by half the
// barycentric coordinates, below), so the two coincide (no gap, as in projective skinning).
// Fixed per-vertex targets, not a relative tie "point - surface point = 0" or a barycentric
// row: a stiff relative tie has no fixed place, and two barycentric rows on one triangle with
// different targets fix the triangle's slope with a lever (targets 0.1 mm apart at
// coordinates 0.9 / 0.8 put its corners 1 mm apart), so where ties disagree (rolled lips:
// each lip inside the other and both inside the teeth) the least-squares solution moved whole
// regions far (57 mm for penetrations of 2.8 mm). With fixed per-vertex targets every tied
// point moves toward places within its penetration depth.
void contact_rows(const SimulationMesh& mesh, const Contact& c, const Positions& skin, const Positions& vertices,
                  double weight, std::vector<TargetElement>& rows, std::vector<Eigen::RowVector3d>& targets) {
  const CollisionSet& set = mesh.collisions[static_cast<std::size_t>(c.set)];
  const Positions& sv = surface_positions(set, skin, vertices);
  Eigen::RowVector3d q = Eigen::RowVector3d::Zero();
  for (int k = 0; k < 3; ++k) q += c.bary[k] * sv.row(set.surface(c.triangle, k));
  const Eigen::RowVector3d meet = set.surface_on_skin ? Eigen::RowVector3d(0.5 * (skin.row(c.point) + q)) : q;
  rows.push_back({PointRow{{c.point}, {1.0}}, weight});
  targets.push_back(meet);
  if (!set.surface_on_skin) return;
  // Where two sheets press into each other every point is a contact and a corner of the
  // other side's contacts; with the corners' rows as heavy as the point's the two pulls
  // balanced short of the surface (alex_rom_3 frame 1400: 2 points left 20-38 um inside after
  // 30 rounds); at half weight the point's own contact leads and they close.
  constexpr double kCornerShare = 0.5;
  for (int k = 0; k < 3; ++k) {
    const int32_t v = set.surface(c.triangle, k);
    if (!(c.bary[k] > 0) || v == c.point) continue;
    rows.push_back({PointRow{{v}, {1.0}}, kCornerShare * weight * c.bary[k]});
    targets.push_back(skin.row(v) + meet - q);
  }
}

double contact_gap(const SimulationMesh& mesh, const Contact& c, const Positions& skin, const Positions& vertices) {
  const CollisionSet& set = mesh.collisions[static_cast<std::size_t>(c.set)];
  const Positions& sv = surface_positions(set, skin, vertices);
  Eigen::RowVector3d q = Eigen::RowVector3d::Zero();
  for (int k = 0; k < 3; ++k) q += c.bary[k] * sv.row(set.surface(c.triangle, k));
  return (skin.row(c.point) - q).norm();
}

// Skin points the surface step may move: the collision sets' points and skin surfaces, and
// two rings of S around them so the correction fades out smoothly.
std::vector<char> active_points(const SimulationMesh& mesh) {
  const auto ns = static_cast<std::size_t>(mesh.skin_count());
  std::vector<char> active(ns, 0);
  for (const CollisionSet& set : mesh.collisions) {
    for (int32_t p : set.points) active[static_cast<std::size_t>(p)] = 1;
    if (set.surface_on_skin)
      for (Eigen::Index i = 0; i < set.surface.size(); ++i) active[static_cast<std::size_t>(set.surface.data()[i])] = 1;
  }
  for (int ring = 0; ring < 2; ++ring) {
    std::vector<char> next = active;
    for (Eigen::Index t = 0; t < mesh.skin_triangles.rows(); ++t) {
      bool touches = false;
      for (int k = 0; k < 3; ++k) touches = touches || active[static_cast<std::size_t>(mesh.skin_triangles(t, k))];
      if (touches)
        for (int k = 0; k < 3; ++k) next[static_cast<std::size_t>(mesh.skin_triangles(t, k))] = 1;
    }
    active.swap(next);
  }
  return active;
}
}  // namespace

Vec3 closest_point_barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

SurfaceTopology::SurfaceTopology(const TriIndices& tris) {
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      edges.emplace_back(edge_key(tris(t, k), tris(t, (k + 1) % 3)), t);
      vertex_faces.emplace(tris(t, k), t);
    }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i == 1) boundary.insert(edges[i].first.first), boundary.insert(edges[i].first.second);
    i = j;
  }
}

CollisionTopology::CollisionTopology(const SimulationMesh& mesh) : rest_skin(embed(mesh.skin, mesh.rest)) {
  for (const CollisionSet& set : mesh.collisions) sets.emplace_back(set.surface);
}

std::vector<Contact> find_penetrations(const SimulationMesh& mesh, const Positions& skin, const Positions& vertices,
                                       double tolerance) {
  return find_penetrations(mesh, CollisionTopology(mesh), skin, vertices, tolerance);
}

namespace {
// Triangle bounding boxes of a set's surface grown by its max_distance: a cheap reject.
std::vector<Eigen::AlignedBox3d> surface_boxes(const CollisionSet& set, const Positions& sv) {
  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(set.surface.rows()));
  for (Eigen::Index t = 0; t < set.surface.rows(); ++t) {
    auto& box = boxes[static_cast<std::size_t>(t)];
    for (int k = 0; k < 3; ++k) box.extend(Vec3(sv.row(set.surface(t, k)).transpose()));
    box.min().array() -= set.max_distance;
    box.max().array() += set.max_distance;
  }
  return boxes;
}

// The closest point of set `si`'s surface to skin point p and its signed depth (positive
// behind the surface); false when none lies within max_distance or the closest feature is on
// the boundary.
bool locate(const SimulationMesh& mesh, const CollisionTopology& topology, std::size_t si, int32_t p,
            const Positions& skin, const Positions& vertices, const std::vector<Eigen::AlignedBox3d>& boxes,
            Contact& out) {
  const CollisionSet& set = mesh.collisions[si];
  const Positions& sv = surface_positions(set, skin, vertices);
  const Vec3 q = skin.row(p).transpose();
  Contact best{static_cast<int>(si), p, -1, Vec3::Zero(), 0};
  double best_d2 = set.max_distance * set.max_distance;
  for (Eigen::Index t = 0; t < set.surface.rows(); ++t) {
    if (!boxes[static_cast<std::size_t>(t)].contains(q)) continue;
    if (set.surface_on_skin && (set.surface(t, 0) == p || set.surface(t, 1) == p || set.surface(t, 2) == p))
      continue;  // a point never collides with its own triangles
    const Vec3 a = sv.row(set.surface(t, 0)), b = sv.row(set.surface(t, 1)), c = sv.row(set.surface(t, 2));
    const Vec3 bc = closest_point_barycentric(q, a, b, c);
    const double d2 = (q - (bc[0] * a + bc[1] * b + bc[2] * c)).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best.triangle = static_cast<int32_t>(t);
      best.bary = bc;
    }
  }
  if (best.triangle < 0) return false;
  Vec3 n;
  if (!feature_normal(topology.sets[si], set.surface, sv, best.triangle, best.bary, n) || !(n.norm() > 0)) return false;
  n.normalize();
  Vec3 point = Vec3::Zero(), rest_point = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const int32_t v = set.surface(best.triangle, k);
    point += best.bary[k] * sv.row(v).transpose();
    if (set.surface_on_skin) rest_point += best.bary[k] * topology.rest_skin.row(v).transpose();
  }
  best.depth = -(q - point).dot(n);
  // A lip sheet is open: behind it by more than the slack already at rest (along today's
  // normal) means the point never crossed it (a curled lip's normal turned toward it: on
  // all_mouth_half lower-lip points 6-7 mm below the upper lip, 13 mm "behind" it at rest).
  // The slack keeps pressed lips, whose closest points lie a few mm apart along the sheet at
  // rest (press_shrug on the template: 138 of 143 contacts with 3 mm, 36 with 1 mm).
  constexpr double kRestSideSlack = 3e-3;  // m
  if (set.surface_on_skin && best.depth > 0 &&
      (Vec3(topology.rest_skin.row(p).transpose()) - rest_point).dot(n) < -kRestSideSlack)
    return false;
  out = best;
  return true;
}
}  // namespace

std::vector<Contact> find_penetrations(const SimulationMesh& mesh, const CollisionTopology& topology,
                                       const Positions& skin, const Positions& vertices, double tolerance) {
  std::vector<Contact> out;
  for (std::size_t si = 0; si < mesh.collisions.size(); ++si) {
    const CollisionSet& set = mesh.collisions[si];
    const auto boxes = surface_boxes(set, surface_positions(set, skin, vertices));
    Contact c{};
    for (int32_t p : set.points)
      if (locate(mesh, topology, si, p, skin, vertices, boxes, c) && c.depth > tolerance) out.push_back(c);
  }
  return out;
}

namespace {
// Skin-strain elements of S's triangles touching an active point, at rest in `shape_of`.
std::vector<TriangleElement> shape_elements(const SimulationMesh& mesh, const std::vector<char>& active,
                                            const Positions& shape_of, double weight) {
  std::vector<TriangleElement> shape;
  for (Eigen::Index t = 0; t < mesh.skin_triangles.rows(); ++t) {
    TriangleElement e;
    bool touches = false;
    for (int c = 0; c < 3; ++c) {
      const int32_t p = mesh.skin_triangles(t, c);
      e.corner[static_cast<std::size_t>(c)] = PointRow{{p}, {1.0}};
      touches = touches || active[static_cast<std::size_t>(p)];
    }
    if (!touches) continue;
    TriangleStrainGroup::set_rest(e, shape_of.row(mesh.skin_triangles(t, 0)).transpose(),
                                  shape_of.row(mesh.skin_triangles(t, 1)).transpose(),
                                  shape_of.row(mesh.skin_triangles(t, 2)).transpose());
    e.weight = weight;
    shape.push_back(std::move(e));
  }
  return shape;
}

// The contact step's fixed part on S's active points: shape, anchors (lip points to their
// targets, the others weakly to the solved skin); `solve` adds the current contacts.
struct SurfaceProblem {
  const SimulationMesh& mesh;
  const Positions& vertices;
  const Eigen::VectorXd& skin_area;
  const SolverSettings& settings;
  ThreadPool* pool;
  double length = 1;
  std::vector<char> active;
  std::vector<TriangleElement> shape;
  std::vector<TargetElement> anchor;
  std::vector<Eigen::RowVector3d> anchor_rows;

  // One projective solve with `contacts`, from and into `skin`.
  void solve(const std::map<std::pair<int, int32_t>, Contact>& contacts, Positions& skin, SolveStats& stats) const {
    const PhysicalConstants& k = physical_constants();
    const double pa = k.pascal_per_weight_unit;
    Model m;
    m.pinned.resize(active.size());
    for (std::size_t p = 0; p < active.size(); ++p) m.pinned[p] = !active[p];
    add_group(m, std::make_unique<TriangleStrainGroup>("lip shape", shape, pa));
    const Eigen::Index anchor_row = m.rows;
    add_group(m, std::make_unique<TargetGroup>("lip anchor", anchor));
    std::vector<TargetElement> ties;
    std::vector<Eigen::RowVector3d> tie_targets;
    for (const auto& [key, c] : contacts)
      contact_rows(mesh, c, skin, vertices,
                   pa * settings.collision_weight * skin_area[c.point] / k.target_layer_thickness_m, ties,
                   tie_targets);
    const Eigen::Index tie_row = m.rows;
    if (!ties.empty()) add_group(m, std::make_unique<TargetGroup>("contacts", std::move(ties)));
    const System sys(m);
    Positions P = Positions::Zero(sys.rows(), 3);
    for (std::size_t i = 0; i < anchor_rows.size(); ++i) P.row(anchor_row + static_cast<Eigen::Index>(i)) = anchor_rows[i];
    for (std::size_t i = 0; i < tie_targets.size(); ++i) P.row(tie_row + static_cast<Eigen::Index>(i)) = tie_targets[i];
    SolverSettings st = settings;
    st.record_energy = false;
    run_projective_dynamics(FrameProblem{&m, &sys, nullptr, nullptr, length}, P, skin, st, pool, stats);
  }
};

// Shape of the skin (strain relative to it), a weak pull back to the solved skin, stiff
// contacts. With lip targets the lip points follow their targets instead, and the shape is
// the targets' own: the volumetric result is not a shape to keep there (see collisions.h).
SurfaceProblem surface_problem(const SimulationMesh& mesh, const Positions& skin, const Positions& vertices,
                               const Eigen::VectorXd& skin_area, const SolverSettings& settings, ThreadPool* pool,
                               const LipTargets* lips) {
  constexpr double kShapeKpa = 1.0, kAnchorKpa = 0.01;
  const PhysicalConstants& k = physical_constants();
  SurfaceProblem sp{mesh, vertices, skin_area, settings, pool,
                    (skin.colwise().maxCoeff() - skin.colwise().minCoeff()).norm(), active_points(mesh), {}, {}, {}};
  std::vector<char> lip_point(sp.active.size(), 0);
  if (lips)
    for (const CollisionSet& set : mesh.collisions)
      for (int32_t p : set.points) lip_point[static_cast<std::size_t>(p)] = 1;
  sp.shape = shape_elements(mesh, sp.active, lips ? lips->targets : skin, kShapeKpa * k.skin_thickness_m);
  for (std::size_t p = 0; p < sp.active.size(); ++p)
    if (sp.active[p]) {
      const auto i = static_cast<Eigen::Index>(p);
      const bool lip = lip_point[p] != 0;
      const double w =
          lip ? lips->weight[i] : k.pascal_per_weight_unit * kAnchorKpa * skin_area[i] / k.target_layer_thickness_m;
      sp.anchor.push_back({PointRow{{static_cast<int32_t>(p)}, {1.0}}, w});
      sp.anchor_rows.push_back(lip ? lips->targets.row(i) : skin.row(i));
    }
  return sp;
}

// Contacts slide: each persisting one moves to its point's newest closest surface point,
// and is released once the point is clearly outside (pulled there by other contacts);
// holding it at a stale place over-constrains lips that touch each other and the teeth.
void slide_contacts(const SimulationMesh& mesh, const CollisionTopology& topology, const Positions& skin,
                    const Positions& vertices, double tolerance, std::map<std::pair<int, int32_t>, Contact>& contacts) {
  if (contacts.empty()) return;
  std::vector<std::vector<Eigen::AlignedBox3d>> boxes;
  for (const CollisionSet& set : mesh.collisions) boxes.push_back(surface_boxes(set, surface_positions(set, skin, vertices)));
  for (auto it = contacts.begin(); it != contacts.end();) {
    Contact now{};
    const auto si = static_cast<std::size_t>(it->second.set);
    if (locate(mesh, topology, si, it->second.point, skin, vertices, boxes[si], now) && now.depth > -tolerance) {
      it->second = now;
      ++it;
    } else {
      it = contacts.erase(it);
    }
  }
}
}  // namespace

namespace {
using ContactMap = std::map<std::pair<int, int32_t>, Contact>;  // one per (set, point)

double largest_gap(const SimulationMesh& mesh, const ContactMap& contacts, const Positions& skin,
                   const Positions& vertices) {
  double gap = 0;
  for (const auto& [key, c] : contacts) gap = std::max(gap, contact_gap(mesh, c, skin, vertices));
  return gap;
}

// The rounds of detect, tie, solve from `base` (the uncorrected skin) with its penetrations
// `found`. A round is kept only when it leaves fewer penetrating points than the best so far
// (the uncorrected skin to begin with: contacts never add penetrations), or as many (none)
// with closer contacts, and moves no point farther from the uncorrected skin than twice the
// deepest penetration found there plus a slack (a tie moves both sides: on two slabs pressed
// 3 mm into each other points move up to 5.9 mm): a correction the measured depth cannot
// explain is the contact step injecting energy, and stops the rounds. Rounds go on while a
// point penetrates or a contact's two sides are farther apart than the tolerance.
// How far the round moved the points its contacts act on (each contact's point and, on a
// surface over S, its triangle's corners) from where the step started. The rest of S may
// move too, the surface solve settling further toward its fixed point; that is no contact's
// correction (measured over all of S, a lip point 10 um inside the lower teeth had its round
// rejected by a 1 mm move elsewhere).
double contact_correction(const SimulationMesh& mesh, const ContactMap& contacts, const Positions& base,
                          const Positions& skin) {
  double largest = 0;
  auto moved = [&](int32_t p) { largest = std::max(largest, (skin.row(p) - base.row(p)).norm()); };
  for (const auto& [key, c] : contacts) {
    moved(c.point);
    const CollisionSet& set = mesh.collisions[static_cast<std::size_t>(c.set)];
    if (set.surface_on_skin)
      for (int k = 0; k < 3; ++k) moved(set.surface(c.triangle, k));
  }
  return largest;
}

void contact_rounds(const SimulationMesh& mesh, const CollisionTopology& topology, const SurfaceProblem& surface,
                    const Positions& base, const Positions& vertices, std::vector<Contact> found,
                    const SolverSettings& settings, CollisionResult& r) {
  constexpr double kCorrectionSlack = 1e-3;  // m, beyond the deepest penetration
  const double tol = settings.penetration_tolerance;
  double deepest = 0;
  for (const Contact& c : found) deepest = std::max(deepest, c.depth);
  const double depth_bound = 2 * deepest + kCorrectionSlack;
  Positions best_skin = base;
  std::size_t best_found = found.size();
  double best_gap = INFINITY, gap = 0;
  ContactMap contacts;
  r.skin = base;
  while ((!found.empty() || gap > tol) && r.rounds < settings.collision_rounds) {
    slide_contacts(mesh, topology, r.skin, vertices, tol, contacts);
    for (const Contact& c : found) contacts[{c.set, c.point}] = c;
    SolveStats stats;
    surface.solve(contacts, r.skin, stats);
    r.iterations += stats.iterations;
    ++r.rounds;
    const double correction = contact_correction(mesh, contacts, base, r.skin);
    r.largest_round_correction = std::max(r.largest_round_correction, correction);
    if (!std::isfinite(correction) || correction > depth_bound) {
      ++r.rejected_rounds;
      break;
    }
    found = find_penetrations(mesh, topology, r.skin, vertices, tol);
    gap = largest_gap(mesh, contacts, r.skin, vertices);
    if (found.size() < best_found || (found.empty() && best_found == 0 && gap < best_gap)) {
      best_skin = r.skin;
      best_found = found.size();
      best_gap = gap;
      r.contacts = static_cast<int>(contacts.size());
      r.max_correction = correction;
    }
  }
  r.skin = std::move(best_skin);
  r.penetrating_after = static_cast<int>(best_found);
  r.max_contact_gap = std::isfinite(best_gap) ? best_gap : 0.0;
}
}  // namespace

CollisionResult resolve_collisions(const SimulationMesh& mesh, const CollisionTopology& topology, const Positions& skin,
                                   const Positions& vertices, const Eigen::VectorXd& skin_area,
                                   const SolverSettings& settings, ThreadPool* pool, const LipTargets* lips) {
  const auto t0 = std::chrono::steady_clock::now();
  CollisionResult r;
  r.skin = skin;
  const bool on_surface = lips != nullptr && lips->targets.rows() == skin.rows() && settings.collision_rounds > 0;
  std::vector<Contact> found;
  if (!on_surface) {
    found = find_penetrations(mesh, topology, skin, vertices, settings.penetration_tolerance);
    r.penetrating_before = r.penetrating_after = static_cast<int>(found.size());
    if (found.empty() || settings.collision_rounds == 0) return r;
  }
  const SurfaceProblem surface =
      surface_problem(mesh, skin, vertices, skin_area, settings, pool, on_surface ? lips : nullptr);
  // What the contacts correct: the solved skin, or with lip targets the lips on their targets
  // (joined to the solved skin around them).
  Positions base = skin;
  if (on_surface) {
    // Start the lips (and every other set's points) on their targets, where this step places
    // them: from the volumetric result the solve met its RMS tolerance with single points
    // still up to 0.8 mm short, inside the other lip.
    for (const CollisionSet& set : mesh.collisions)
      for (int32_t p : set.points) base.row(p) = lips->targets.row(p);
    SolveStats stats;
    surface.solve({}, base, stats);
    r.iterations += stats.iterations;
    found = find_penetrations(mesh, topology, base, vertices, settings.penetration_tolerance);
    r.penetrating_before = static_cast<int>(found.size());
  }
  contact_rounds(mesh, topology, surface, base, vertices, std::move(found), settings, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace softdeca::sim
