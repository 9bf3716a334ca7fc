#include "sim/model.h"

#include <cmath>

#include "sim/bones.h"
#include "sim/constraints_surface.h"
#include "sim/constraints_tet.h"

namespace softdeca::sim {
namespace {

PointRow point_row(const EmbeddedPoints& p, Eigen::Index i) {
  PointRow r;
  for (int k = 0; k < 4; ++k)
    if (p.weight(i, k) != 0) {
      r.vertex.push_back(p.vertex(i, k));
      r.weight.push_back(p.weight(i, k));
    }
  return r;
}

PointRow vertex_row(int32_t v) { return PointRow{{v}, {1.0}}; }

bool all_pinned(const std::vector<char>& pinned, const PointRow& r) {
  for (int32_t v : r.vertex)
    if (!pinned[static_cast<std::size_t>(v)]) return false;
  return true;
}

// Tet elements of one group with their per-element weights; elements on pinned vertices only
// are constant and dropped.
std::vector<TetElement> tet_elements(const Positions& rest, const TetIndices& tets, bool reorient,
                                     const std::vector<char>& pinned, const ParameterSet& p, Param w_volume,
                                     Param w_strain, const Param* target_det, const Param* max_strain,
                                     bool strain_limited, const Eigen::VectorXd* stiffening) {
  std::vector<TetElement> all = TetGroup::make_elements(rest, tets, reorient), kept;
  kept.reserve(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    TetElement& e = all[i];
    bool constant = true;
    for (int32_t v : e.v) constant = constant && pinned[static_cast<std::size_t>(v)];
    if (constant) continue;
    const auto idx = static_cast<Eigen::Index>(i);
    const double k = stiffening && stiffening->size() == tets.rows() ? (*stiffening)[idx] : 1.0;
    e.w_volume = k * p.at(w_volume, idx);
    e.w_strain = k * p.at(w_strain, idx);
    e.target_det = target_det ? p.at(*target_det, idx) : 1.0;
    e.max_strain = !strain_limited ? -INFINITY : max_strain ? p.at(*max_strain, idx) : p.global(Param::max_strain);
    kept.push_back(e);
  }
  return kept;
}

}  // namespace

void add_group(Model& m, std::unique_ptr<ConstraintGroup> g) {
  if (g->elements() == 0) return;
  m.row_offset.push_back(m.rows);
  m.rows += g->rows();
  if (!g->constant_projection()) m.variable_rows = m.rows;
  m.groups.push_back(std::move(g));
}

namespace {

// The projecting tet groups (their rows come first): soft tissue, muscle, connecting tets.
void add_tet_groups(Model& m, const SimulationMesh& mesh, const ParameterSet& p, StrainLimit strain, double pa,
                    const TetStiffening* stiffening) {
  const Param soft_det = Param::target_volume, soft_eps = Param::max_strain;
  add_group(m, std::make_unique<TetGroup>(
             "soft tissue",
             tet_elements(mesh.rest, mesh.soft_tets, false, m.pinned, p, Param::w_soft_volume,
                          Param::w_soft_strain, &soft_det, &soft_eps, true,
                          stiffening ? &stiffening->soft : nullptr),
             strain, pa));
  add_group(m, std::make_unique<TetGroup>(
             "muscle", tet_elements(mesh.rest, mesh.muscle_tets, false, m.pinned, p, Param::w_muscle_volume,
                                    Param::w_muscle_strain, nullptr, nullptr, false,
                                    stiffening ? &stiffening->muscle : nullptr),
             strain, pa));
  // Connecting tets keep their unscaled rest: a scaled skull pushes the tissue it holds.
  add_group(m, std::make_unique<TetGroup>(
             "connecting", tet_elements(mesh.rest, mesh.connecting_tets, true, m.pinned, p,
                                        Param::w_connect_volume, Param::w_connect_strain, nullptr, nullptr, true,
                                        nullptr),
             strain, pa));
}

// The skin's membrane strain, on S's triangles embedded in the tets.
void add_skin_strain(Model& m, const SimulationMesh& mesh, const ParameterSet& p, double pa) {
  const PhysicalConstants& k = physical_constants();
  const Positions skin_rest = embed(mesh.skin, mesh.rest);
  std::vector<TriangleElement> tris;
  for (Eigen::Index t = 0; t < mesh.skin_triangles.rows(); ++t) {
    TriangleElement e;
    for (int c = 0; c < 3; ++c) e.corner[static_cast<std::size_t>(c)] = point_row(mesh.skin, mesh.skin_triangles(t, c));
    if (all_pinned(m.pinned, e.corner[0]) && all_pinned(m.pinned, e.corner[1]) && all_pinned(m.pinned, e.corner[2]))
      continue;
    TriangleStrainGroup::set_rest(e, skin_rest.row(mesh.skin_triangles(t, 0)).transpose(),
                                  skin_rest.row(mesh.skin_triangles(t, 1)).transpose(),
                                  skin_rest.row(mesh.skin_triangles(t, 2)).transpose());
    e.weight = p.at(Param::w_skin_strain, t) * k.skin_thickness_m;
    tris.push_back(std::move(e));
  }
  add_group(m, std::make_unique<TriangleStrainGroup>("skin strain", std::move(tris), pa));
}

// The skull's shell: membrane strain and bending on its triangles, at the scaled rest.
void add_skull_shell(Model& m, const SimulationMesh& mesh, const ParameterSet& p, double pa) {
  const PhysicalConstants& k = physical_constants();
  std::vector<TriangleElement> tris;
  for (Eigen::Index t = 0; t < mesh.skull_triangles.rows(); ++t) {
    TriangleElement e;
    bool constant = true;
    for (int c = 0; c < 3; ++c) {
      e.corner[static_cast<std::size_t>(c)] = vertex_row(mesh.skull_triangles(t, c));
      constant = constant && m.pinned[static_cast<std::size_t>(mesh.skull_triangles(t, c))];
    }
    if (constant) continue;
    TriangleStrainGroup::set_rest(e, m.scaled_rest.row(mesh.skull_triangles(t, 0)).transpose(),
                                  m.scaled_rest.row(mesh.skull_triangles(t, 1)).transpose(),
                                  m.scaled_rest.row(mesh.skull_triangles(t, 2)).transpose());
    e.weight = p.at(Param::w_skull_strain, t) * k.skull_shell_thickness_m;
    tris.push_back(std::move(e));
  }
  add_group(m, std::make_unique<TriangleStrainGroup>("skull strain", std::move(tris), pa));

  Eigen::VectorXd w(mesh.vertex_count());
  for (Eigen::Index v = 0; v < w.size(); ++v) w[v] = p.at(Param::w_skull_bending, v);
  std::vector<BendingElement> bend = make_bending_elements(m.scaled_rest, mesh.skull_triangles,
                                                           k.skull_shell_thickness_m, w);
  std::vector<BendingElement> kept;
  for (auto& e : bend)
    if (!all_pinned(m.pinned, e.laplacian)) kept.push_back(std::move(e));
  add_group(m, std::make_unique<BendingGroup>(std::move(kept), pa));
}

// Dynamics' gamma and beta per skin point, and per landmark as its barycentric blend.
void set_target_dynamics(Model& m, const SimulationMesh& mesh, const ParameterSet& p) {
  const Eigen::Index ns = mesh.skin_count(), nl = mesh.landmark_count();
  m.skin_gamma.resize(ns);
  m.skin_beta.resize(ns);
  for (Eigen::Index i = 0; i < ns; ++i) {
    m.skin_gamma[i] = p.at(Param::dyn_gamma, i);
    m.skin_beta[i] = p.at(Param::dyn_beta, i);
  }
  m.landmark_gamma = Eigen::VectorXd::Zero(nl);
  m.landmark_beta = Eigen::VectorXd::Zero(nl);
  for (Eigen::Index l = 0; l < nl; ++l)
    for (int j = 0; j < 3; ++j) {
      m.landmark_gamma[l] += mesh.landmark_weights(l, j) * m.skin_gamma[mesh.landmark_points(l, j)];
      m.landmark_beta[l] += mesh.landmark_weights(l, j) * m.skin_beta[mesh.landmark_points(l, j)];
    }
}

// Targets: weight w * area / layer thickness (eq. 14 and 22), divided by gamma when dynamic.
void add_target_groups(Model& m, const SimulationMesh& mesh, const ParameterSet& p, TargetMode mode, double pa) {
  const PhysicalConstants& k = physical_constants();
  const Eigen::Index ns = mesh.skin_count(), nl = mesh.landmark_count();
  const bool dynamic = mode == TargetMode::kDynamic;
  const Param skin_weight = nl > 0 ? Param::w_regularisation : Param::w_target;
  if (ns > 0) {
    std::vector<TargetElement> el(static_cast<std::size_t>(ns));
    for (Eigen::Index i = 0; i < ns; ++i) {
      auto& e = el[static_cast<std::size_t>(i)];
      e.point = point_row(mesh.skin, i);
      e.weight = pa * p.at(skin_weight, i) * m.skin_area[i] / k.target_layer_thickness_m;
      if (dynamic) e.weight /= m.skin_gamma[i];
    }
    m.skin_row = m.rows;
    add_group(m, std::make_unique<TargetGroup>("skin targets", std::move(el)));
  }
  m.landmark_rows.clear();
  if (nl > 0) {
    // Each landmark stands for an equal share of the skin's area.
    const double area = m.skin_area.sum() / static_cast<double>(nl);
    std::vector<TargetElement> el(static_cast<std::size_t>(nl));
    for (Eigen::Index l = 0; l < nl; ++l) {
      const SparseRow r = landmark_row(mesh, l);
      auto& e = el[static_cast<std::size_t>(l)];
      e.point = PointRow{r.vertex, r.weight};
      e.weight = pa * p.at(Param::w_landmark, l) * area / k.target_layer_thickness_m;
      if (dynamic) e.weight /= m.landmark_gamma[l];
      m.landmark_rows.push_back(e.point);
    }
    m.landmark_row = m.rows;
    add_group(m, std::make_unique<TargetGroup>("landmarks", std::move(el)));
  }
}

// Lumped masses of the tissue tets, for gravity.
Eigen::VectorXd lumped_masses(const SimulationMesh& mesh) {
  const PhysicalConstants& k = physical_constants();
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(mesh.vertex_count());
  for (const TetIndices* tets : {&mesh.soft_tets, &mesh.muscle_tets})
    for (Eigen::Index t = 0; t < tets->rows(); ++t) {
      const Eigen::Vector3d a = mesh.rest.row((*tets)(t, 0)), b = mesh.rest.row((*tets)(t, 1)),
                            c = mesh.rest.row((*tets)(t, 2)), d = mesh.rest.row((*tets)(t, 3));
      const double vol = std::abs((b - a).dot((c - a).cross(d - a))) / 6.0;
      for (int j = 0; j < 4; ++j) mass[(*tets)(t, j)] += k.tissue_density_kg_m3 * vol / 4.0;
    }
  return mass;
}

}  // namespace

Model build_model(const SimulationMesh& mesh, const ParameterSet& p, TargetMode mode, StrainLimit strain,
                  const TetStiffening* stiffening) {
  const double pa = physical_constants().pascal_per_weight_unit;
  Model m;
  m.scaled_rest = scaled_rest(mesh, p);
  m.pinned = pinned_mask(mesh);
  add_tet_groups(m, mesh, p, strain, pa, stiffening);  // the projecting groups' rows come first
  add_skin_strain(m, mesh, p, pa);
  add_skull_shell(m, mesh, p, pa);
  m.skin_area = skin_point_areas(mesh);
  set_target_dynamics(m, mesh, p);
  add_target_groups(m, mesh, p, mode, pa);
  m.mass = lumped_masses(mesh);
  return m;
}

Eigen::Vector3d gravity_direction(const ParameterSet& p) {
  const double deg = 3.14159265358979323846 / 180.0;
  const double t = p.global(Param::gravity_tilt) * deg, a = p.global(Param::gravity_azimuth) * deg;
  return Eigen::Vector3d(std::sin(t) * std::cos(a), -std::cos(t), std::sin(t) * std::sin(a));
}

Positions gravity_forces(const Model& model, const ParameterSet& p) {
  const PhysicalConstants& k = physical_constants();
  const Eigen::Vector3d g = k.standard_gravity_m_s2 *
                            (p.global(Param::gravity_strength) * gravity_direction(p) - k.capture_gravity_direction);
  Positions f(model.mass.size(), 3);
  for (Eigen::Index v = 0; v < model.mass.size(); ++v) f.row(v) = model.mass[v] * g.transpose();
  return f;
}

}  // namespace softdeca::sim
