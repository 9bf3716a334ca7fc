#include "fit/avatar_frame.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "stream/arkit_names.h"

namespace softdeca::fit {
namespace {

// A shape's motion counts where it exceeds this share of the shape's largest: the rest is an
// exporter's rounding (bodies carry 1e-7 "motion" in many files).
constexpr double kMotionShare = 0.002;

// Left/Right pairs whose shapes move one side's part of the face (not "mouthLeft"/"jawLeft",
// which move the whole mouth or jaw sideways), with the distance between the pair's sides on
// the ICT template, in metres (side_distance; tests/python/test_avatar_frame.py measures them
// again on the template).
struct SidePair {
  const char* stem;
  double template_distance;
};
constexpr SidePair kSidePairs[] = {
    {"browDown", 0.0916},    {"browOuterUp", 0.1029},  {"cheekSquint", 0.1020},   {"eyeBlink", 0.0691},
    {"eyeLookDown", 0.0703}, {"eyeLookIn", 0.0679},    {"eyeLookOut", 0.0679},    {"eyeLookUp", 0.0691},
    {"eyeSquint", 0.0924},   {"eyeWide", 0.0687},      {"mouthDimple", 0.0608},   {"mouthFrown", 0.0638},
    {"mouthLowerDown", 0.0480}, {"mouthPress", 0.0566}, {"mouthSmile", 0.0786},  {"mouthStretch", 0.0765},
    {"mouthUpperUp", 0.0636}, {"noseSneer", 0.0696},
};

// Units a measured scale snaps to when within 25 %: mm, cm, inch, dm, m.
constexpr double kUnits[] = {0.001, 0.01, 0.0254, 0.1, 1.0};
constexpr double kSnap = 1.25;

struct Motion {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // motion-weighted centre of what moves
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // summed deltas over summed lengths
  double spread = 0;  // RMS distance of what moves from the centre, weighted alike
  bool moves = false;
};

// Shapes that move the face forward, out of it, on every rig (the ICT template: 0.63 to 0.94 of
// their motion along +Z): they tell a mirrored mesh from a right-handed one.
constexpr const char* kForwardShapes[] = {"jawForward", "mouthPucker", "mouthFunnel", "cheekPuff"};

int index_of(const std::string& name) { return stream::blendshape_index(name); }

bool starts_with(const char* s, const char* prefix) { return std::string(s).rfind(prefix, 0) == 0; }

void check_finite(const float* p, std::size_t n, const std::string& what) {
  for (std::size_t i = 0; i < n; ++i)
    expect(std::isfinite(p[i]), [&] { return what + " has a non-finite value at vertex " + std::to_string(i / 3); });
}

// The motion-weighted centre and spread of one shape's moving vertices, each vertex weighted by
// its share of the surface (so a mesh dense at the eyes and lips and one evenly meshed agree);
// marks them in `face`.
Motion shape_motion(const AvatarShapes& s, const float* d, const std::vector<double>& area, std::vector<uint8_t>& face) {
  const std::size_t n = s.vertex_count;
  double peak = 0;
  for (std::size_t v = 0; v < n; ++v)
    peak = std::max(peak, Eigen::Vector3d(d[3 * v], d[3 * v + 1], d[3 * v + 2]).norm());
  Motion m;
  if (!(peak > 0)) return m;
  double total = 0, second = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const double motion = Eigen::Vector3d(d[3 * v], d[3 * v + 1], d[3 * v + 2]).norm();
    if (motion <= kMotionShare * peak) continue;
    face[v] = 1;
    const double w = motion * area[v];
    const Eigen::Vector3d x(s.neutral[3 * v], s.neutral[3 * v + 1], s.neutral[3 * v + 2]);
    total += w;
    m.centre += w * x;
    second += w * x.squaredNorm();
    m.direction += Eigen::Vector3d(d[3 * v], d[3 * v + 1], d[3 * v + 2]);
  }
  if (!(total > 0)) return m;  // only vertices on no triangle with area move
  m.centre /= total;
  m.spread = std::sqrt(std::max(0.0, second / total - m.centre.squaredNorm()));
  m.direction /= total;
  m.moves = true;
  return m;
}

// The distance between a Left/Right pair's sides: each side the surface where its own shape
// moves more than the other (each over its largest), weighted by how much more. Rigs split a
// symmetric shape into its sides with a ramp across the face, often a wide one, so each side's
// shape moves the other side too: the shapes' own centres of motion then lie closer together
// than the sides do (a ramp across the whole face halves their distance, and a centimetre head
// reads as inches); what one side moves more than the other stays on that side.
double side_distance(const AvatarShapes& s, const float* dl, const float* dr, const std::vector<double>& area) {
  const std::size_t n = s.vertex_count;
  const auto motion = [](const float* d, std::size_t v) { return Eigen::Vector3d(d[3 * v], d[3 * v + 1], d[3 * v + 2]).norm(); };
  double pl = 0, pr = 0;
  for (std::size_t v = 0; v < n; ++v) pl = std::max(pl, motion(dl, v)), pr = std::max(pr, motion(dr, v));
  if (!(pl > 0 && pr > 0)) return 0;
  Eigen::Vector3d cl = Eigen::Vector3d::Zero(), cr = Eigen::Vector3d::Zero();
  double wl = 0, wr = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const double ml = motion(dl, v), mr = motion(dr, v);
    if (ml <= kMotionShare * pl && mr <= kMotionShare * pr) continue;
    const double more = ml / pl - mr / pr;
    const Eigen::Vector3d x(s.neutral[3 * v], s.neutral[3 * v + 1], s.neutral[3 * v + 2]);
    if (more > 0) cl += more * area[v] * x, wl += more * area[v];
    if (more < 0) cr -= more * area[v] * x, wr -= more * area[v];
  }
  if (!(wl > 0 && wr > 0)) return 0;
  return (cl / wl - cr / wr).norm();
}

double median(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  const std::size_t h = x.size() / 2;
  return x.size() % 2 ? x[h] : 0.5 * (x[h - 1] + x[h]);
}


// Area-weighted normals of the triangles whose corners all move: a face's sum points out of it.
Eigen::Vector3d face_normal_sum(const AvatarShapes& s, const std::vector<uint8_t>& face) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const auto at = [&](int32_t i) { return Eigen::Vector3d(s.neutral[3 * i], s.neutral[3 * i + 1], s.neutral[3 * i + 2]); };
  for (std::size_t t = 0; t < s.triangle_count; ++t) {
    const int32_t* c = s.triangles + 3 * t;
    if (face[static_cast<std::size_t>(c[0])] && face[static_cast<std::size_t>(c[1])] && face[static_cast<std::size_t>(c[2])])
      sum += (at(c[1]) - at(c[0])).cross(at(c[2]) - at(c[0]));
  }
  return sum;
}

// Each vertex's share of the surface: a third of its triangles' areas (1 each without triangles).
std::vector<double> vertex_areas(const AvatarShapes& s) {
  if (s.triangles == nullptr || s.triangle_count == 0) return std::vector<double>(s.vertex_count, 1.0);
  std::vector<double> area(s.vertex_count, 0.0);
  const auto at = [&](int32_t i) { return Eigen::Vector3d(s.neutral[3 * i], s.neutral[3 * i + 1], s.neutral[3 * i + 2]); };
  for (std::size_t t = 0; t < s.triangle_count; ++t) {
    const int32_t* c = s.triangles + 3 * t;
    const double a = (at(c[1]) - at(c[0])).cross(at(c[2]) - at(c[0])).norm() / 6.0;
    for (int k = 0; k < 3; ++k) area[static_cast<std::size_t>(c[k])] += a;
  }
  return area;
}

// Every shape's motion (`area`: vertex_areas); marks the vertices that move in `face`.
std::array<Motion, kShapes> shape_motions(const AvatarShapes& s, const std::vector<double>& area, std::vector<uint8_t>& face) {
  std::array<Motion, kShapes> motion{};
  for (std::size_t i = 0; i < kShapes; ++i)
    if (s.deltas[i] != nullptr) motion[i] = shape_motion(s, s.deltas[i], area, face);
  return motion;
}

}  // namespace

ShapeCentres shape_centres(const AvatarShapes& s) {
  std::vector<uint8_t> face(s.vertex_count, 0);
  const std::array<Motion, kShapes> motion = shape_motions(s, vertex_areas(s), face);
  ShapeCentres c;
  for (std::size_t i = 0; i < kShapes; ++i) {
    c.moves[i] = motion[i].moves;
    c.centres[i] = motion[i].centre;
    c.spreads[i] = motion[i].spread;
  }
  return c;
}

std::string axis_name(const Eigen::Vector3d& up) {
  Eigen::Index k = 0;
  up.cwiseAbs().maxCoeff(&k);
  return std::string(up[k] < 0 ? "-" : "+") + "XYZ"[k];
}

double snap_unit(double measured) {
  double unit = measured;
  for (const double u : kUnits)
    if (std::fabs(std::log(measured / u)) < std::log(kSnap)) unit = u;
  return unit;
}

AvatarFrame avatar_frame(const AvatarShapes& s) {
  require(s.neutral != nullptr && s.vertex_count > 0, "the avatar has no vertices");
  check_finite(s.neutral, 3 * s.vertex_count, "the neutral mesh");
  require(s.triangles != nullptr || s.triangle_count == 0, "triangle_count without triangles");
  for (std::size_t i = 0; i < 3 * s.triangle_count; ++i)
    expect(s.triangles[i] >= 0 && static_cast<std::size_t>(s.triangles[i]) < s.vertex_count,
           [&] { return "triangle " + std::to_string(i / 3) + " has a vertex index outside the mesh"; });
  for (std::size_t i = 0; i < kShapes; ++i)
    if (s.deltas[i] != nullptr)
      check_finite(s.deltas[i], 3 * s.vertex_count, std::string("blendshape ") + stream::blendshape_name(i));
  AvatarFrame f;
  f.face.assign(s.vertex_count, 0);
  const std::vector<double> area = vertex_areas(s);
  const std::array<Motion, kShapes> motion = shape_motions(s, area, f.face);
  for (std::size_t i = 0; i < kShapes; ++i) {
    f.shapes_used += motion[i].moves;
    f.moves[i] = motion[i].moves;
    f.centres[i] = motion[i].centre;
    f.spreads[i] = motion[i].spread;
  }
  f.face_vertices = static_cast<std::size_t>(std::count(f.face.begin(), f.face.end(), uint8_t{1}));
  require(f.shapes_used > 0, "none of the avatar's ARKit blendshapes moves a vertex: no face to fit");

  // The subject's left: the Left shapes' centres minus the Right ones', summed (far-apart pairs
  // weigh most); the unit: the template's distances over the avatar's, pair by pair.
  Eigen::Vector3d left = Eigen::Vector3d::Zero();
  std::vector<double> scales;
  Eigen::Vector3d eyes = Eigen::Vector3d::Zero();
  int eye_pairs = 0;
  double eye_distance = 0;
  for (const SidePair& p : kSidePairs) {
    const auto li = static_cast<std::size_t>(index_of(std::string(p.stem) + "Left"));
    const auto ri = static_cast<std::size_t>(index_of(std::string(p.stem) + "Right"));
    const Motion& l = motion[li];
    const Motion& r = motion[ri];
    if (!l.moves || !r.moves) continue;
    const Eigen::Vector3d d = l.centre - r.centre;
    left += d;
    const double sides = side_distance(s, s.deltas[li], s.deltas[ri], area);
    if (sides > 0) scales.push_back(p.template_distance / sides);
    if (starts_with(p.stem, "eye")) {
      eyes += 0.5 * (l.centre + r.centre);
      eye_distance += d.norm();
      ++eye_pairs;
    }
  }
  require(left.norm() > 0 && !scales.empty(),
          "the avatar needs a Left/Right pair of ARKit shapes that move one side of the face (eyeBlink, "
          "browDown, mouthSmile, ...) to tell its left from its right; it has none");
  f.left = left.normalized();

  // Up: the eye and brow shapes' centres above the mouth and jaw shapes'.
  Eigen::Vector3d upper = Eigen::Vector3d::Zero(), lower = Eigen::Vector3d::Zero();
  int n_upper = 0, n_lower = 0;
  for (std::size_t i = 0; i < kShapes; ++i) {
    if (!motion[i].moves) continue;
    const char* name = stream::blendshape_name(i);
    if (starts_with(name, "eye") || starts_with(name, "brow")) upper += motion[i].centre, ++n_upper;
    if (starts_with(name, "mouth") || starts_with(name, "jaw")) lower += motion[i].centre, ++n_lower;
  }
  require(n_upper > 0 && n_lower > 0,
          "the avatar needs eye or brow shapes and mouth or jaw shapes to tell up from down; it has " +
              std::string(n_upper ? "no mouth or jaw shape" : "no eye or brow shape"));
  Eigen::Vector3d up = upper / n_upper - lower / n_lower;
  up -= up.dot(f.left) * f.left;
  require(up.norm() > 0, "the avatar's eye and mouth shapes move the same place: no up direction");
  f.up = up.normalized();
  f.forward = f.left.cross(f.up);
  f.up_axis = axis_name(f.up);

  f.metres_per_unit_measured = median(scales);
  f.metres_per_unit = snap_unit(f.metres_per_unit_measured);
  if (eye_pairs) {
    f.eye_distance = eye_distance / eye_pairs;
    f.eyes = eyes / eye_pairs;
  }
  // Which way is out of the face: the forward shapes' motion; without them the face's normals
  // (outward for a consistently wound mesh). Either disagreeing with left x up: a mirrored mesh.
  Eigen::Vector3d ahead = Eigen::Vector3d::Zero();
  for (const char* name : kForwardShapes) ahead += motion[static_cast<std::size_t>(index_of(name))].direction;
  if (ahead.norm() == 0 && s.triangles != nullptr) ahead = face_normal_sum(s, f.face);
  f.mirrored = ahead.dot(f.forward) < 0;
  if (f.mirrored) f.forward = -f.forward;
  return f;
}

}  // namespace softdeca::fit
