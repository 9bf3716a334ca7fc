// Physics simulator part of the C ABI: checked conversions between the flat C structs and
// sim::Simulator. Every entry point runs under guarded(): no exception crosses the boundary.
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "api/error_boundary.h"
#include "api/handles.h"
#include "sim/simulator.h"

struct softdeca_sim {
  std::unique_ptr<softdeca::sim::Simulator> sim;
  softdeca::sim::Positions vertices, skin;  // last good output
};

namespace {
using namespace softdeca;
using namespace softdeca::api;
using namespace softdeca::sim;

constexpr std::size_t kMaxCount = std::size_t{1} << 30;

void check_count(std::size_t n, const char* name) {
  require(n < kMaxCount, std::string(name) + " is implausibly large");
}

Positions points(const float* xyz, std::size_t count, const char* name) {
  check_count(count, name);
  if (count == 0) return Positions(0, 3);
  require_not_null(xyz, name);
  require_finite(xyz, count * 3, name);
  Positions p(static_cast<Eigen::Index>(count), 3);
  for (std::size_t i = 0; i < count * 3; ++i) p.data()[i] = xyz[i];
  return p;
}

template <int K>
Eigen::Matrix<int32_t, Eigen::Dynamic, K, Eigen::RowMajor> indices(const int32_t* idx, std::size_t count,
                                                                   const char* name) {
  check_count(count, name);
  Eigen::Matrix<int32_t, Eigen::Dynamic, K, Eigen::RowMajor> m(static_cast<Eigen::Index>(count), K);
  if (count == 0) return m;
  require_not_null(idx, name);
  std::memcpy(m.data(), idx, count * K * sizeof(int32_t));
  return m;
}

std::vector<int32_t> index_list(const int32_t* idx, std::size_t count, const char* name) {
  check_count(count, name);
  if (count == 0) return {};
  require_not_null(idx, name);
  return std::vector<int32_t>(idx, idx + count);
}

template <int K>
Eigen::Matrix<double, Eigen::Dynamic, K, Eigen::RowMajor> weights(const float* w, std::size_t count, const char* name) {
  Eigen::Matrix<double, Eigen::Dynamic, K, Eigen::RowMajor> m(static_cast<Eigen::Index>(count), K);
  if (count == 0) return m;
  require_not_null(w, name);
  require_finite(w, count * K, name);
  for (std::size_t i = 0; i < count * K; ++i) m.data()[i] = w[i];
  return m;
}

Eigen::Vector3d pivot(const float* p) {
  if (!p) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  require_finite(p, 3, "pivot");
  return Eigen::Vector3d(p[0], p[1], p[2]);
}

SimulationMesh to_mesh(const softdeca_sim_mesh& c) {
  SimulationMesh m;
  m.rest = points(c.vertices, c.vertex_count, "vertices");
  m.soft_tets = indices<4>(c.soft_tets, c.soft_tet_count, "soft_tets");
  m.muscle_tets = indices<4>(c.muscle_tets, c.muscle_tet_count, "muscle_tets");
  m.connecting_tets = indices<4>(c.connecting_tets, c.connecting_tet_count, "connecting_tets");
  m.skull_triangles = indices<3>(c.skull_triangles, c.skull_triangle_count, "skull_triangles");
  m.cranium.vertices = index_list(c.cranium_vertices, c.cranium_vertex_count, "cranium_vertices");
  m.jaw.vertices = index_list(c.jaw_vertices, c.jaw_vertex_count, "jaw_vertices");
  m.cranium.pinned = c.cranium_pinned != 0;
  m.jaw.pinned = c.jaw_pinned != 0;
  m.cranium.pivot = pivot(c.cranium_pivot);
  m.jaw.pivot = pivot(c.jaw_pivot);
  m.skin.vertex = indices<4>(c.skin_vertices, c.skin_count, "skin_vertices");
  m.skin.weight = weights<4>(c.skin_weights, c.skin_count, "skin_weights");
  m.skin_triangles = indices<3>(c.skin_triangles, c.skin_triangle_count, "skin_triangles");
  m.landmark_points = indices<3>(c.landmark_points, c.landmark_count, "landmark_points");
  m.landmark_weights = weights<3>(c.landmark_weights, c.landmark_count, "landmark_weights");
  check_count(c.collision_count, "collision_count");
  if (c.collision_count) require_not_null(c.collisions, "collisions");
  for (std::size_t i = 0; i < c.collision_count; ++i) {
    const softdeca_sim_collision_set& s = c.collisions[i];
    require_struct(&s, "collisions[i]");
    CollisionSet set;
    set.name = "collision set " + std::to_string(i);
    set.points = index_list(s.points, s.point_count, "collision points");
    set.surface = indices<3>(s.surface, s.surface_triangle_count, "collision surface");
    set.surface_on_skin = s.surface_on_skin != 0;
    require(std::isfinite(s.max_distance), "collision max_distance is not finite", SOFTDECA_ERROR_NON_FINITE);
    set.max_distance = s.max_distance;
    m.collisions.push_back(std::move(set));
  }
  return m;
}

SolverSettings to_settings(const softdeca_sim_settings* c) {
  SolverSettings s;
  if (!c) return s;
  require_struct(c, "settings");
  require(std::isfinite(c->tolerance) && std::isfinite(c->collision_weight) && std::isfinite(c->penetration_tolerance),
          "settings contain a non-finite value", SOFTDECA_ERROR_NON_FINITE);
  require(c->max_iterations <= 1000000 && c->anderson_window <= 1024 && c->collision_rounds <= 1024,
          "settings.max_iterations, anderson_window or collision_rounds is implausibly large");
  require(c->threads <= 1024, "settings.threads must be in [0, 1024]");
  s.max_iterations = static_cast<int>(c->max_iterations);
  s.tolerance = c->tolerance;
  s.anderson_window = static_cast<int>(c->anderson_window);
  s.threads = static_cast<int>(c->threads);
  s.strain_limit = c->paper_strain_rule ? StrainLimit::kPaperRotation : StrainLimit::kNearestInSet;
  s.collision_rounds = static_cast<int>(c->collision_rounds);
  s.collision_weight = c->collision_weight;
  s.penetration_tolerance = c->penetration_tolerance;
  validate(s);
  return s;
}

Eigen::Isometry3d transform(const float* t, const char* name) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (!t) return T;
  require_finite(t, 12, name);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) T.matrix()(r, c) = t[4 * r + c];
  return T;
}

FrameInput to_frame(const softdeca_sim& h, const softdeca_sim_frame* f) {
  require_struct(f, "frame");
  const SimulationMesh& m = h.sim->mesh();
  require(f->skin_count == static_cast<std::size_t>(m.skin_count()),
          "frame->skin_count is " + std::to_string(f->skin_count) + ", the mesh has " + std::to_string(m.skin_count()) +
              " skin points");
  require(f->landmark_count == static_cast<std::size_t>(m.landmark_count()),
          "frame->landmark_count is " + std::to_string(f->landmark_count) + ", the mesh has " +
              std::to_string(m.landmark_count()) + " landmarks");
  require(f->warm_start == nullptr || f->warm_start_count == static_cast<std::size_t>(m.vertex_count()),
          "frame->warm_start_count must equal the vertex count");
  FrameInput in;
  in.skin_targets = points(f->skin_targets, f->skin_count, "frame->skin_targets");
  in.landmark_targets = points(f->landmark_targets, f->landmark_count, "frame->landmark_targets");
  in.bones.cranium = transform(f->cranium_transform, "frame->cranium_transform");
  in.bones.jaw = transform(f->jaw_transform, "frame->jaw_transform");
  if (f->warm_start) in.warm_start = points(f->warm_start, f->warm_start_count, "frame->warm_start");
  return in;
}

void to_stats(const SolveStats& s, softdeca_sim_stats* out) {
  if (!out) return;
  require_struct(out, "stats");
  out->iterations = static_cast<uint32_t>(s.iterations);
  out->converged = s.converged ? SOFTDECA_TRUE : SOFTDECA_FALSE;
  out->relative_step = s.relative_step;
  out->estimated_error = s.estimated_error;
  out->contraction = s.contraction;
  out->energy = s.energy;
  out->target_rms = s.target_rms;
  out->local_seconds = s.local_seconds;
  out->global_seconds = s.global_seconds;
  out->factor_seconds = s.factor_seconds;
  out->total_seconds = s.total_seconds;
  out->penetrating_before = static_cast<uint32_t>(s.penetrating_before);
  out->penetrating_after = static_cast<uint32_t>(s.penetrating_after);
  out->contacts = static_cast<uint32_t>(s.contacts);
  out->inverted_elements = static_cast<uint32_t>(s.inverted_elements);
  out->max_target_distance = s.max_target_distance;
  out->collision_rounds = static_cast<uint32_t>(s.collision_rounds);
  out->rejected_collision_rounds = static_cast<uint32_t>(s.rejected_collision_rounds);
  out->max_contact_gap = s.max_contact_gap;
  out->max_contact_correction = s.max_contact_correction;
}

void copy_out(const Positions& p, float* out, std::size_t count, const char* name) {
  require_not_null(out, name);
  require(count == static_cast<std::size_t>(p.rows()),
          std::string(name) + ": count is " + std::to_string(count) + ", expected " + std::to_string(p.rows()),
          SOFTDECA_ERROR_BUFFER_TOO_SMALL);
  for (Eigen::Index i = 0; i < p.size(); ++i) out[i] = static_cast<float>(p.data()[i]);
}

void store(softdeca_sim& h, FrameResult&& r) {
  h.vertices = std::move(r.vertices);
  h.skin = std::move(r.skin);
}

Param parameter(uint32_t index) {
  expect(index < parameter_table().size(), [&] {
    return "parameter index " + std::to_string(index) + " is not below the " + std::to_string(parameter_table().size()) +
           " simulator parameters";
  });
  return static_cast<Param>(index);
}
// One frame through `step` (a static solve or a dynamic step): stats out, result stored.
void advance(softdeca_sim* sim, const softdeca_sim_frame* frame, softdeca_sim_stats* stats,
             FrameResult (Simulator::*step)(const FrameInput&)) {
  require_not_null(sim, "sim");
  if (stats) require_struct(stats, "stats");
  FrameResult r = (sim->sim.get()->*step)(to_frame(*sim, frame));
  to_stats(r.stats, stats);
  store(*sim, std::move(r));
}
}  // namespace

extern "C" {

SOFTDECA_API softdeca_status softdeca_sim_get_parameter_count(uint32_t* out_count) {
  return guarded(__func__, [&] {
    require_not_null(out_count, "out_count");
    *out_count = static_cast<uint32_t>(parameter_table().size());
  });
}

SOFTDECA_API softdeca_status softdeca_sim_get_parameter_info(uint32_t index, softdeca_parameter_info* out) {
  return guarded(__func__, [&] {
    require_struct(out, "out_info");
    const ParameterSpec& p = parameter_spec(parameter(index));
    out->name = p.name.c_str();
    out->unit = p.unit.c_str();
    out->domain = p.domain.c_str();
    out->description = p.description.c_str();
    out->default_value = p.default_value;
    out->minimum = p.minimum;
    out->maximum = p.maximum;
    out->log_scale = p.log_scale ? SOFTDECA_TRUE : SOFTDECA_FALSE;
  });
}

SOFTDECA_API softdeca_status softdeca_sim_find_parameter(const char* name, uint32_t* out_index) {
  return guarded(__func__, [&] {
    require_not_null(name, "name");
    require_not_null(out_index, "out_index");
    *out_index = static_cast<uint32_t>(find_parameter(name));
  });
}

SOFTDECA_API softdeca_status softdeca_sim_get_parameters_json(const char** out_json) {
  return guarded(__func__, [&] {
    require_not_null(out_json, "out_json");
    *out_json = parameters_json();
  });
}

SOFTDECA_API softdeca_status softdeca_sim_settings_init(softdeca_sim_settings* s) {
  return guarded(__func__, [&] {
    require_struct(s, "settings");
    const SolverSettings d;
    s->max_iterations = static_cast<uint32_t>(d.max_iterations);
    s->tolerance = static_cast<float>(d.tolerance);
    s->anderson_window = static_cast<uint32_t>(d.anderson_window);
    s->threads = static_cast<uint32_t>(d.threads);
    s->paper_strain_rule = d.strain_limit == StrainLimit::kPaperRotation ? SOFTDECA_TRUE : SOFTDECA_FALSE;
    s->collision_rounds = static_cast<uint32_t>(d.collision_rounds);
    s->collision_weight = static_cast<float>(d.collision_weight);
    s->penetration_tolerance = static_cast<float>(d.penetration_tolerance);
  });
}

SOFTDECA_API softdeca_status softdeca_sim_create(const softdeca_sim_mesh* mesh, const softdeca_sim_settings* settings,
                                                 softdeca_sim** out_sim) {
  return guarded(__func__, [&] {
    require_not_null(out_sim, "out_sim");
    require_struct(mesh, "mesh");
    create_handle(out_sim, "out_sim", [&](softdeca_sim& h) {
      h.sim = std::make_unique<Simulator>(to_mesh(*mesh), to_settings(settings));
      h.vertices = h.sim->rest_positions();
      h.skin = embed(h.sim->mesh().skin, h.vertices);
    });
  });
}

SOFTDECA_API void softdeca_sim_destroy(softdeca_sim* sim) {
  destroy_handle(__func__, sim);
}

SOFTDECA_API softdeca_status softdeca_sim_get_vertex_count(const softdeca_sim* sim, uint32_t* out_count) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    require_not_null(out_count, "out_count");
    *out_count = static_cast<uint32_t>(sim->vertices.rows());
  });
}

SOFTDECA_API softdeca_status softdeca_sim_get_skin_count(const softdeca_sim* sim, uint32_t* out_count) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    require_not_null(out_count, "out_count");
    *out_count = static_cast<uint32_t>(sim->skin.rows());
  });
}

SOFTDECA_API softdeca_status softdeca_sim_set_parameter(softdeca_sim* sim, uint32_t index, double value) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    sim->sim->parameters().set(parameter(index), value);
  });
}

SOFTDECA_API softdeca_status softdeca_sim_get_parameter(const softdeca_sim* sim, uint32_t index, double* out_value) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    require_not_null(out_value, "out_value");
    *out_value = sim->sim->parameters().global(parameter(index));
  });
}

SOFTDECA_API softdeca_status softdeca_sim_set_parameter_field(softdeca_sim* sim, uint32_t index, const float* values,
                                                              uint32_t count) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    const Param p = parameter(index);
    check_count(count, "count");
    require(count == 0 || values != nullptr, "values is null");
    Eigen::VectorXd v(static_cast<Eigen::Index>(count));
    for (std::size_t i = 0; i < count; ++i) v[static_cast<Eigen::Index>(i)] = values[i];
    sim->sim->parameters().set_field(p, v);
  });
}

SOFTDECA_API softdeca_status softdeca_sim_solve_static(softdeca_sim* sim, const softdeca_sim_frame* frame,
                                                       softdeca_sim_stats* stats) {
  return guarded(__func__, [&] { advance(sim, frame, stats, &Simulator::solve_static); });
}

SOFTDECA_API softdeca_status softdeca_sim_step_dynamic(softdeca_sim* sim, const softdeca_sim_frame* frame,
                                                       softdeca_sim_stats* stats) {
  return guarded(__func__, [&] { advance(sim, frame, stats, &Simulator::step_dynamic); });
}

SOFTDECA_API softdeca_status softdeca_sim_reset_dynamics(softdeca_sim* sim) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    sim->sim->reset_dynamics();
  });
}

SOFTDECA_API softdeca_status softdeca_sim_solve_static_batch(softdeca_sim* sim, const softdeca_sim_frame* frames,
                                                             uint32_t frame_count, float* out_skin,
                                                             uint32_t out_skin_count, softdeca_sim_stats* stats) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    check_count(frame_count, "frame_count");
    require(frame_count > 0, "frame_count must be at least 1");
    require_not_null(frames, "frames");
    require_not_null(out_skin, "out_skin");
    const std::size_t ns = static_cast<std::size_t>(sim->sim->mesh().skin_count());
    require(out_skin_count == frame_count * ns,
            "out_skin_count is " + std::to_string(out_skin_count) + ", expected frame_count * skin_count = " +
                std::to_string(frame_count * ns),
            SOFTDECA_ERROR_BUFFER_TOO_SMALL);
    if (stats)
      for (std::size_t f = 0; f < frame_count; ++f) require_struct(&stats[f], "stats[f]");
    std::vector<FrameInput> in;
    in.reserve(frame_count);
    for (std::size_t f = 0; f < frame_count; ++f) in.push_back(to_frame(*sim, &frames[f]));
    std::vector<FrameResult> out = sim->sim->solve_static_batch(in);
    for (std::size_t f = 0; f < frame_count; ++f) {
      copy_out(out[f].skin, out_skin + f * ns * 3, ns, "out_skin");
      if (stats) to_stats(out[f].stats, &stats[f]);
    }
    store(*sim, std::move(out.back()));
  });
}

SOFTDECA_API softdeca_status softdeca_sim_get_vertices(const softdeca_sim* sim, float* out_vertices,
                                                       uint32_t vertex_count) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    copy_out(sim->vertices, out_vertices, vertex_count, "out_vertices");
  });
}

SOFTDECA_API softdeca_status softdeca_sim_get_skin(const softdeca_sim* sim, float* out_skin, uint32_t skin_count) {
  return guarded(__func__, [&] {
    require_not_null(sim, "sim");
    copy_out(sim->skin, out_skin, skin_count, "out_skin");
  });
}

}  // extern "C"
