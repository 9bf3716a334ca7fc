#include "prepare/rest_physics.h"

#include <Eigen/SparseCholesky>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <string>

#include "core/error.h"
#include "geometry/nearest_points.h"
#include "prepare/contact_sets.h"
#include "sim/parameters.h"

namespace softdeca::prepare {

namespace {
using Triplets = std::vector<Eigen::Triplet<double>>;

// The per-element field of parameter `index`'s map on the physics' domain, built from the one
// kind of values that domain reads: per vertex (tets through their skin vertex, skin points) or
// per face (skin triangles). Empty where the domain has no per-element values.
Eigen::VectorXd field_of(sim::Domain domain, const ParameterState& params, int index, std::size_t faces,
                         std::size_t vertices, const std::vector<std::int32_t>& soft_tet_vertex,
                         const std::vector<std::int32_t>& muscle_tet_vertex) {
  const bool per_face = domain == sim::Domain::kSkinTriangle;
  const bool per_vertex =
      domain == sim::Domain::kSoftTet || domain == sim::Domain::kMuscleTet || domain == sim::Domain::kSkinPoint;
  if (!per_face && !per_vertex) return {};
  std::vector<float> values(per_face ? faces : vertices);
  if (per_face) params.face_matrix({index}, values.data());
  else params.vertex_matrix({index}, values.data());
  const auto take = [&](const std::vector<std::int32_t>& at) {
    Eigen::VectorXd f(static_cast<Eigen::Index>(at.size()));
    for (std::size_t i = 0; i < at.size(); ++i) f[static_cast<Eigen::Index>(i)] = values[static_cast<std::size_t>(at[i])];
    return f;
  };
  if (domain == sim::Domain::kSoftTet) return take(soft_tet_vertex);
  if (domain == sim::Domain::kMuscleTet) return take(muscle_tet_vertex);
  return Eigen::Map<const Eigen::VectorXf>(values.data(), static_cast<Eigen::Index>(values.size())).cast<double>();
}

// Barycentric coordinates of each skin point in its embedding tet of the carried fill (negative
// outside it): the carry follows S only approximately, and the template's coordinates would
// leave S off its targets at rest. A degenerate tet keeps the bundle's weights.
void embed_own_skin(const sim::Positions& fill, const sim::Positions& skin, sim::EmbeddedPoints& e) {
  for (Eigen::Index i = 0; i < e.size(); ++i) {
    const Eigen::RowVector3d x0 = fill.row(e.vertex(i, 0));
    Eigen::Matrix3d edges;
    for (int k = 0; k < 3; ++k) edges.col(k) = (fill.row(e.vertex(i, k + 1)) - x0).transpose();
    if (!(std::abs(edges.determinant()) > 1e-18)) continue;
    const Eigen::Vector3d b = edges.partialPivLu().solve((skin.row(i) - x0).transpose());
    e.weight(i, 0) = 1.0 - b.sum();
    for (int k = 0; k < 3; ++k) e.weight(i, k + 1) = b[k];
  }
}
}  // namespace

void add_fill_stiffness(const sim::Positions& x, const sim::TetIndices& tets, double scale, Triplets& out) {
  for (Eigen::Index t = 0; t < tets.rows(); ++t) {
    Eigen::Matrix3d e;
    for (int j = 0; j < 3; ++j) e.col(j) = (x.row(tets(t, j + 1)) - x.row(tets(t, 0))).transpose();
    const double det = e.determinant();
    if (!(std::abs(det) > 0)) continue;  // a degenerate tet adds no energy (the bundle's fill has none)
    Eigen::Matrix<double, 4, 3> g;
    g.bottomRows<3>() = e.inverse();
    g.row(0) = -g.bottomRows<3>().colwise().sum();
    const double vol = std::abs(det) / 6.0;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) out.emplace_back(tets(t, a), tets(t, b), scale * vol * g.row(a).dot(g.row(b)));
  }
}

sim::Positions carry_fill(const RestHead& head, const sim::Positions& neutral_skin) {
  const Eigen::Index n = head.vertices.rows(), ns = head.skin.size();
  require(neutral_skin.rows() == ns, "carry_fill: the neutral skin does not match the bundle's skin");
  Triplets k, b;
  for (Eigen::Index i = 0; i < ns; ++i)
    for (int c = 0; c < 4; ++c)
      if (head.skin.weight(i, c) != 0 && head.carry_weight[static_cast<std::size_t>(i)] != 0)
        b.emplace_back(i, head.skin.vertex(i, c), head.skin.weight(i, c) * head.carry_weight[static_cast<std::size_t>(i)]);
  Eigen::SparseMatrix<double> bw(ns, n);
  bw.setFromTriplets(b.begin(), b.end());
  add_fill_stiffness(head.vertices, head.soft_tets, head.carry_smoothness, k);
  add_fill_stiffness(head.vertices, head.muscle_tets, head.carry_smoothness, k);
  Eigen::SparseMatrix<double> system(n, n);
  system.setFromTriplets(k.begin(), k.end());
  system += Eigen::SparseMatrix<double>(bw.transpose() * bw);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(system);
  if (ldlt.info() != Eigen::Success)
    throw Error(SOFTDECA_ERROR_FORMAT, "the bundle's rest head cannot be carried (its carry system is singular)");
  // The embedded rest skin B V0 (every point, unweighted) and the avatar's departure from it.
  sim::Positions embedded = sim::embed(head.skin, head.vertices);
  const Eigen::MatrixXd rhs = bw.transpose() * (neutral_skin - embedded);
  sim::Positions out = head.vertices + ldlt.solve(rhs);
  return out;
}

RestPhysics::RestPhysics(const RestHead& head, const bundle::Manifest& m, const float* neutral,
                         const std::vector<std::int32_t>& skin_triangles, int threads)
    : head_(head), m_(m) {
  const auto ns = static_cast<Eigen::Index>(m.skin_vertices);
  targets_ = Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>>(neutral, ns, 3).cast<double>();
  sim::SimulationMesh mesh;
  const sim::Positions fill = carry_fill(head, targets_);
  const Eigen::Index nf = fill.rows();
  const auto nu = static_cast<Eigen::Index>(head.teeth_upper.size()), nl = static_cast<Eigen::Index>(head.teeth_lower.size());
  mesh.rest.resize(nf + nu + nl, 3);
  mesh.rest.topRows(nf) = fill;
  for (Eigen::Index i = 0; i < nu + nl; ++i) {
    const std::int32_t v = i < nu ? head.teeth_upper[static_cast<std::size_t>(i)] : head.teeth_lower[static_cast<std::size_t>(i - nu)];
    for (int c = 0; c < 3; ++c) mesh.rest(nf + i, c) = neutral[3 * static_cast<std::size_t>(v) + static_cast<std::size_t>(c)];
  }
  mesh.soft_tets = head.soft_tets;
  mesh.muscle_tets = head.muscle_tets;
  mesh.connecting_tets.resize(0, 4);
  mesh.skull_triangles.resize(0, 3);
  mesh.cranium.vertices = head.cranium;
  mesh.jaw.vertices = head.jaw;
  mesh.skin = head.skin;
  embed_own_skin(fill, targets_, mesh.skin);
  mesh.skin_triangles = Eigen::Map<const sim::TriIndices>(skin_triangles.data(),
                                                           static_cast<Eigen::Index>(skin_triangles.size() / 3), 3);
  mesh.landmark_points.resize(0, 3);
  mesh.landmark_weights.resize(0, 3);
  if (head.has_contacts) {
    const auto offset = [](const sim::TriIndices& t, Eigen::Index by) { return sim::TriIndices(t.array() + static_cast<std::int32_t>(by)); };
    mesh.collisions = contact_sets(head.contacts, targets_, skin_triangles, offset(head.upper_teeth, nf),
                                   offset(head.lower_teeth, nf + nu));
  }
  // Each tet takes the parameter values of the skin vertex nearest its centroid on this head,
  // as the data's regions do.
  const auto centroids = [&](const sim::TetIndices& tets) {
    geometry::Sites c(tets.rows(), 3);
    for (Eigen::Index t = 0; t < tets.rows(); ++t)
      c.row(t) = 0.25 * (fill.row(tets(t, 0)) + fill.row(tets(t, 1)) + fill.row(tets(t, 2)) + fill.row(tets(t, 3)));
    return c;
  };
  soft_tet_vertex_ = geometry::nearest_sites(targets_, centroids(head.soft_tets));
  muscle_tet_vertex_ = geometry::nearest_sites(targets_, centroids(head.muscle_tets));
  sim::SolverSettings settings;
  settings.tolerance = head.tolerance;
  settings.max_iterations = head.max_iterations;
  settings.threads = threads;
  settings.record_energy = false;
  try {
    sim_ = std::make_unique<sim::Simulator>(std::move(mesh), settings);
  } catch (const Error& e) {
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT,
                std::string("the physics at prepare cannot use this head (the bundle's head carried to its neutral): ") + e.what());
  }
}

sim::Positions RestPhysics::solve(const ParameterState& params) {
  sim::ParameterSet& p = sim_->parameters();
  const std::size_t nf = static_cast<std::size_t>(m_.skin_triangles), nv = static_cast<std::size_t>(m_.skin_vertices);
  for (std::size_t i = 0; i < m_.parameters.size(); ++i) {
    const int index = static_cast<int>(i);
    const sim::Param id = head_.parameter_ids.at(i);
    if (params.kind(index) == ParameterState::Kind::Global) {
      p.set(id, params.global(index));
      continue;
    }
    const Eigen::VectorXd field =
        field_of(sim::parameter_domain(id), params, index, nf, nv, soft_tet_vertex_, muscle_tet_vertex_);
    if (field.size() == 0) p.set(id, params.global(index));  // no per-element values there
    else p.set_field(id, field);
  }
  sim::FrameInput in;
  in.skin_targets = targets_;
  sim::FrameResult r = sim_->solve_static(in);
  iterations_ = r.stats.iterations;
  return std::move(r.skin);
}

}  // namespace softdeca::prepare
