#include "sim/collisions.h"

#include <Eigen/Geometry>
#include <cmath>

#include "sim/parameters.h"

namespace softdeca::sim {
namespace {
using Vec3 = Eigen::Vector3d;

// Positions and rows (as combinations of simulated vertices) of a set's surface vertices.
const Positions& surface_positions(const CollisionSet& set, const Positions& skin, const Positions& x) {
  return set.surface_on_skin ? skin : x;
}

PointRow skin_point_row(const SimulationMesh& mesh, int32_t p) {
  PointRow r;
  for (int k = 0; k < 4; ++k)
    if (mesh.skin.weight(p, k) != 0) {
      r.vertex.push_back(mesh.skin.vertex(p, k));
      r.weight.push_back(mesh.skin.weight(p, k));
    }
  return r;
}

PointRow surface_vertex_row(const SimulationMesh& mesh, const CollisionSet& set, int32_t v) {
  return set.surface_on_skin ? skin_point_row(mesh, v) : PointRow{{v}, {1.0}};
}

void add_scaled(PointRow& into, const PointRow& r, double s) {
  for (std::size_t k = 0; k < r.vertex.size(); ++k) {
    bool merged = false;
    for (std::size_t e = 0; e < into.vertex.size() && !merged; ++e)
      if (into.vertex[e] == r.vertex[k]) {
        into.weight[e] += s * r.weight[k];
        merged = true;
      }
    if (!merged) {
      into.vertex.push_back(r.vertex[k]);
      into.weight.push_back(s * r.weight[k]);
    }
  }
}

PointRow contact_row(const SimulationMesh& mesh, const Contact& c) {
  const CollisionSet& set = mesh.collisions[static_cast<std::size_t>(c.set)];
  PointRow row;
  add_scaled(row, skin_point_row(mesh, c.point), 1.0);
  for (int k = 0; k < 3; ++k)
    add_scaled(row, surface_vertex_row(mesh, set, set.surface(c.triangle, k)), -c.bary[k]);
  return row;
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

std::vector<Contact> find_penetrations(const SimulationMesh& mesh, const Positions& x, double tolerance) {
  std::vector<Contact> out;
  if (mesh.collisions.empty()) return out;
  const Positions skin = embed(mesh.skin, x);
  for (std::size_t si = 0; si < mesh.collisions.size(); ++si) {
    const CollisionSet& set = mesh.collisions[si];
    const Positions& sv = surface_positions(set, skin, x);
    // Area-weighted vertex normals of the surface (only its own vertices are touched).
    Positions normal = Positions::Zero(sv.rows(), 3);
    for (Eigen::Index t = 0; t < set.surface.rows(); ++t) {
      const Vec3 a = sv.row(set.surface(t, 0)), b = sv.row(set.surface(t, 1)), c = sv.row(set.surface(t, 2));
      const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();
      for (int k = 0; k < 3; ++k) normal.row(set.surface(t, k)) += n;
    }
    for (int32_t p : set.points) {
      const Vec3 q = skin.row(p).transpose();
      Contact best{static_cast<int>(si), p, -1, Vec3::Zero(), 0};
      double best_d2 = set.max_distance * set.max_distance;
      for (Eigen::Index t = 0; t < set.surface.rows(); ++t) {
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
      if (best.triangle < 0) continue;
      Vec3 point = Vec3::Zero(), n = Vec3::Zero();
      for (int k = 0; k < 3; ++k) {
        point += best.bary[k] * sv.row(set.surface(best.triangle, k)).transpose();
        n += best.bary[k] * normal.row(set.surface(best.triangle, k)).normalized().transpose();
      }
      if (!(n.norm() > 0)) continue;
      best.depth = -(q - point).dot(n.normalized());
      if (best.depth > tolerance) out.push_back(best);
    }
  }
  return out;
}

std::unique_ptr<TargetGroup> contact_group(const SimulationMesh& mesh, const std::vector<Contact>& contacts,
                                           const Eigen::VectorXd& skin_area, double collision_weight) {
  const PhysicalConstants& k = physical_constants();
  std::vector<TargetElement> el;
  el.reserve(contacts.size());
  for (const Contact& c : contacts)
    el.push_back(TargetElement{contact_row(mesh, c), k.pascal_per_weight_unit * collision_weight * skin_area[c.point] /
                                                         k.target_layer_thickness_m});
  return std::make_unique<TargetGroup>("contacts", std::move(el));
}

double max_contact_gap(const SimulationMesh& mesh, const std::vector<Contact>& contacts, const Positions& x) {
  double gap = 0;
  for (const Contact& c : contacts) gap = std::max(gap, contact_row(mesh, c).apply(x).norm());
  return gap;
}

}  // namespace softdeca::sim
