// Runtime part of the C ABI: handles over runtime::Model and runtime::Avatar, and the argument
// checks every call makes before touching them.
#include <algorithm>
#include <memory>
#include <string>

#include "api/error_boundary.h"
#include "api/handles.h"
#include "api/runtime_handles.h"
#include "bundle/bundle_files.h"
#include "runtime/frame_batch.h"

namespace {
using namespace softdeca;
using namespace softdeca::api;
using runtime::Avatar;
using runtime::Model;

constexpr std::size_t kMaxThreads = 8;

// The avatar, on its mesh: its frames, maps and memory.
runtime::FittedAvatar& on_mesh(softdeca_avatar* a) {
  require_not_null(a, "avatar");
  return *a->avatar;
}

// Its core, which holds parameters, identity, preparation and dynamics (the registered
// template's avatar; the mesh's own for the template's topology).
Avatar& avatar_of(softdeca_avatar* a) { return on_mesh(a).core(); }

const Avatar& avatar_of(const softdeca_avatar* a) {
  require_not_null(a, "avatar");
  return a->avatar->core();
}

runtime::Output output_of(const softdeca_output* o) {
  require_struct(o, "output");
  return {o->vertices, o->vertex_capacity, o->normals, o->normal_capacity};
}

runtime::ModelOptions model_options(const softdeca_model_options* o) {
  runtime::ModelOptions opts;
  if (!o) return opts;
  require_struct(o, "options");
  require(o->prepare_threads <= 64, "options->prepare_threads must be at most 64");
  opts.prepare_threads = o->prepare_threads == 0 ? 1 : static_cast<int>(o->prepare_threads);
  if (o->memory_budget_mib) opts.memory_budget_bytes = std::uint64_t{o->memory_budget_mib} << 20;
  return opts;
}

int parameter_index(const Model& m, uint32_t index) {
  require(index < m.manifest().parameters.size(), "parameter index " + std::to_string(index) + " is not below the bundle's " +
                                                      std::to_string(m.manifest().parameters.size()) + " parameters");
  return static_cast<int>(index);
}
}  // namespace

extern "C" {

SOFTDECA_API softdeca_status softdeca_model_load(const char* path, const softdeca_model_options* options,
                                                 softdeca_model** out_model) {
  return guarded(__func__, [&] {
    require_not_null(path, "path");
    require_not_null(out_model, "out_model");
    const auto opts = model_options(options);
    create_handle(out_model, "out_model", [&](softdeca_model& h) {
      h.model = Model::load(bundle::BundleFiles::from_path(path), opts);
    });
  });
}

SOFTDECA_API softdeca_status softdeca_model_load_memory(const void* data, uint32_t byte_count,
                                                        const softdeca_model_options* options, softdeca_model** out_model) {
  return guarded(__func__, [&] {
    require_not_null(data, "data");
    require_not_null(out_model, "out_model");
    require(byte_count > 0, "byte_count is 0");
    const auto opts = model_options(options);
    create_handle(out_model, "out_model", [&](softdeca_model& h) {
      h.model = Model::load(bundle::BundleFiles::from_tar(static_cast<const std::uint8_t*>(data), byte_count), opts);
    });
  });
}

SOFTDECA_API void softdeca_model_destroy(softdeca_model* model) {
  destroy_handle(__func__, model);
}

SOFTDECA_API softdeca_status softdeca_model_get_info(const softdeca_model* model, softdeca_model_info* out_info) {
  return guarded(__func__, [&] {
    const auto& m = model_of(model).manifest();
    require_struct(out_info, "out_info");
    out_info->format_version = static_cast<uint32_t>(m.format_version);
    out_info->head_vertex_count = static_cast<uint32_t>(m.head_vertices);
    out_info->skin_vertex_count = static_cast<uint32_t>(m.skin_vertices);
    out_info->skin_triangle_count = static_cast<uint32_t>(m.skin_triangles);
    out_info->latent_size = static_cast<uint32_t>(m.latent);
    out_info->identity_size = static_cast<uint32_t>(m.identity);
    out_info->blendshape_count = bundle::kBlendshapeCount;
    out_info->parameter_count = static_cast<uint32_t>(m.parameters.size());
    out_info->landmark_count = static_cast<uint32_t>(m.landmarks.size());
    out_info->arkit_vertex_count = static_cast<uint32_t>(m.arkit_vertex_count);
    out_info->has_softdeca = m.has_softdeca ? SOFTDECA_TRUE : SOFTDECA_FALSE;
    out_info->has_sparse = m.has_sparse ? SOFTDECA_TRUE : SOFTDECA_FALSE;
    out_info->untrained = m.untrained ? SOFTDECA_TRUE : SOFTDECA_FALSE;
    out_info->dynamics_frame_rate_hz = static_cast<float>(m.frame_rate_hz);
  });
}

SOFTDECA_API softdeca_status softdeca_model_get_parameter_info(const softdeca_model* model, uint32_t index,
                                                          softdeca_parameter_info* out_info) {
  return guarded(__func__, [&] {
    const Model& m = model_of(model);
    require_struct(out_info, "out_info");
    const auto& p = m.manifest().parameters[static_cast<std::size_t>(parameter_index(m, index))];
    out_info->name = p.name.c_str();
    out_info->unit = p.unit.c_str();
    out_info->domain = p.localisable ? p.domain.c_str() : "global";
    out_info->description = p.description.c_str();
    out_info->default_value = p.default_value;
    out_info->minimum = p.minimum;
    out_info->maximum = p.maximum;
    out_info->log_scale = p.log_scale ? 1 : 0;
  });
}

SOFTDECA_API softdeca_status softdeca_model_find_parameter(const softdeca_model* model, const char* name,
                                                           uint32_t* out_index) {
  return guarded(__func__, [&] {
    const Model& m = model_of(model);
    require_not_null(name, "name");
    require_not_null(out_index, "out_index");
    const int i = m.manifest().find_parameter(name);
    require(i >= 0, std::string("the bundle has no parameter '") + name + "'");
    *out_index = static_cast<uint32_t>(i);
  });
}

SOFTDECA_API softdeca_status softdeca_model_get_landmark_vertices(const softdeca_model* model, int32_t* out_vertices,
                                                                  uint32_t capacity) {
  return guarded(__func__, [&] {
    const auto& lm = model_of(model).manifest().landmarks;
    require_not_null(out_vertices, "out_vertices");
    require(capacity >= lm.size(), "capacity " + std::to_string(capacity) + " is below the " + std::to_string(lm.size()) +
                                       " landmarks",
            SOFTDECA_ERROR_BUFFER_TOO_SMALL);
    for (std::size_t i = 0; i < lm.size(); ++i) out_vertices[i] = lm[i].arkit_vertex;
  });
}

SOFTDECA_API softdeca_status softdeca_model_get_skin_triangles(const softdeca_model* model, int32_t* out_triangles,
                                                               uint32_t capacity) {
  return guarded(__func__, [&] {
    const auto& t = model_of(model).skin_triangles();
    require_not_null(out_triangles, "out_triangles");
    require(capacity >= t.size() / 3, "capacity " + std::to_string(capacity) + " is below the " + std::to_string(t.size() / 3) +
                                          " skin triangles",
            SOFTDECA_ERROR_BUFFER_TOO_SMALL);
    std::copy(t.begin(), t.end(), out_triangles);
  });
}

SOFTDECA_API softdeca_status softdeca_model_evaluate_landmarks(const softdeca_model* model, const float* vertices,
                                                               uint32_t vertex_count, float* out_points, uint32_t point_capacity) {
  return guarded(__func__, [&] {
    const Model& mo = model_of(model);
    const auto& m = mo.manifest();
    require_not_null(vertices, "vertices");
    require_not_null(out_points, "out_points");
    require(vertex_count == static_cast<std::size_t>(m.skin_vertices) || vertex_count == static_cast<std::size_t>(m.head_vertices),
            "vertex_count " + std::to_string(vertex_count) + " is neither the skin's " + std::to_string(m.skin_vertices) +
                " nor the head's " + std::to_string(m.head_vertices));
    require(point_capacity >= m.landmarks.size(), "point_capacity is below the " + std::to_string(m.landmarks.size()) + " landmarks",
            SOFTDECA_ERROR_BUFFER_TOO_SMALL);
    require_finite(vertices, vertex_count * 3, "vertices");
    const auto& tri = mo.skin_triangles();
    for (std::size_t i = 0; i < m.landmarks.size(); ++i) {
      const auto& l = m.landmarks[i];
      for (int c = 0; c < 3; ++c) {
        double p = 0;
        for (int k = 0; k < 3; ++k)
          p += l.bary[k] * vertices[3 * static_cast<std::size_t>(tri[3 * static_cast<std::size_t>(l.triangle) + static_cast<std::size_t>(k)]) +
                                    static_cast<std::size_t>(c)];
        out_points[3 * i + static_cast<std::size_t>(c)] = static_cast<float>(p);
      }
    }
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_create(const softdeca_model* model, const softdeca_avatar_desc* desc,
                                                    softdeca_avatar** out_avatar) {
  return guarded(__func__, [&] {
    model_of(model);
    require_struct(desc, "desc");
    require_not_null(out_avatar, "out_avatar");
    require(desc->threads <= kMaxThreads, "desc->threads must be at most " + std::to_string(kMaxThreads));
    const std::size_t threads = desc->threads == 0 ? 1 : desc->threads;
    const runtime::Precisions precisions = precisions_of(*desc);
    create_handle(out_avatar, "out_avatar",
                  [&](softdeca_avatar& h) { h.avatar = avatar_on_mesh(model, desc->mesh, desc->fit, threads, precisions); });
  });
}

SOFTDECA_API void softdeca_avatar_destroy(softdeca_avatar* avatar) {
  destroy_handle(__func__, avatar);
}

SOFTDECA_API softdeca_status softdeca_avatar_set_parameter(softdeca_avatar* avatar, uint32_t index, double value) {
  return guarded(__func__, [&] {
    Avatar& a = avatar_of(avatar);
    a.set_parameter(parameter_index(a.model(), index), value);
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_set_parameter_faces(softdeca_avatar* avatar, uint32_t index, const float* values,
                                                                 uint32_t face_count) {
  return guarded(__func__, [&] {
    runtime::FittedAvatar& a = on_mesh(avatar);
    a.set_parameter_faces(parameter_index(a.core().model(), index), values, face_count);
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_set_parameter_vertices(softdeca_avatar* avatar, uint32_t index,
                                                                    const float* values, uint32_t vertex_count) {
  return guarded(__func__, [&] {
    runtime::FittedAvatar& a = on_mesh(avatar);
    a.set_parameter_vertices(parameter_index(a.core().model(), index), values, vertex_count);
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_reset_parameters(softdeca_avatar* avatar) {
  return guarded(__func__, [&] { avatar_of(avatar).reset_parameters(); });
}

SOFTDECA_API softdeca_status softdeca_avatar_get_parameter(const softdeca_avatar* avatar, uint32_t index, double* out_value,
                                                           softdeca_bool* out_localised) {
  return guarded(__func__, [&] {
    const Avatar& a = avatar_of(avatar);
    bool localised = false;
    a.get_parameter(parameter_index(a.model(), index), out_value, &localised);
    if (out_localised) *out_localised = localised ? SOFTDECA_TRUE : SOFTDECA_FALSE;
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_get_identity(const softdeca_avatar* avatar, float* out_identity,
                                                          uint32_t capacity) {
  return guarded(__func__, [&] { avatar_of(avatar).get_identity(out_identity, capacity); });
}

SOFTDECA_API softdeca_status softdeca_avatar_set_identity(softdeca_avatar* avatar, const float* identity, uint32_t count) {
  return guarded(__func__, [&] { avatar_of(avatar).set_identity(identity, count); });
}

SOFTDECA_API softdeca_status softdeca_avatar_prepare(softdeca_avatar* avatar) {
  return guarded(__func__, [&] { avatar_of(avatar).prepare(); });
}

SOFTDECA_API softdeca_status softdeca_avatar_evaluate_weights(softdeca_avatar* avatar, const float* weights,
                                                              uint32_t weight_count, const softdeca_output* output) {
  return guarded(__func__, [&] {
    on_mesh(avatar).evaluate_weights(weights, weight_count, output_of(output));
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_evaluate_weights_batch(softdeca_avatar* const* avatars, uint32_t avatar_count,
                                                                    const float* weights, uint32_t weight_count,
                                                                    const softdeca_output* outputs, int32_t* statuses) {
  runtime::FrameBatch batch;
  const softdeca_status call = guarded(__func__, [&] {
    require_not_null(avatars, "avatars");
    require_not_null(outputs, "outputs");
    require_not_null(statuses, "statuses");
    runtime::require_batch_size(avatar_count);
    std::vector<Avatar*> cores(avatar_count, nullptr);
    for (uint32_t i = 0; i < avatar_count; ++i)
      if (avatars[i]) cores[i] = &avatars[i]->avatar->core();
    batch = runtime::encode_weights_batch(cores.data(), avatar_count, weights, weight_count);
  });
  if (call != SOFTDECA_OK) return call;
  // each avatar's frame as its own call; the first failure's message stays for softdeca_last_error
  std::string first_failure;
  for (uint32_t i = 0; i < avatar_count; ++i) {
    const float* w = weights + static_cast<std::size_t>(i) * weight_count;
    statuses[i] = guarded(__func__, [&] { on_mesh(avatars[i]).evaluate_weights(w, weight_count, output_of(&outputs[i]), batch.of(i)); });
    if (statuses[i] != SOFTDECA_OK && first_failure.empty())
      first_failure = std::string("avatar ") + std::to_string(i) + ": " + last_error_text();
  }
  if (first_failure.empty()) clear_last_error();
  else set_last_error(first_failure);
  return SOFTDECA_OK;
}

SOFTDECA_API softdeca_status softdeca_avatar_evaluate_surface(softdeca_avatar* avatar, const float* weights,
                                                              uint32_t weight_count, const float* surface, uint32_t vertex_count,
                                                              const softdeca_output* output) {
  return guarded(__func__, [&] {
    on_mesh(avatar).evaluate_surface(weights, weight_count, surface, vertex_count, output_of(output));
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_calibrate_landmarks(softdeca_avatar* avatar, const float* points,
                                                                 uint32_t point_count) {
  return guarded(__func__, [&] { avatar_of(avatar).calibrate_landmarks(points, point_count); });
}

SOFTDECA_API softdeca_status softdeca_avatar_evaluate_landmarks(softdeca_avatar* avatar, const float* points,
                                                                uint32_t point_count, const softdeca_output* output) {
  return guarded(__func__, [&] {
    on_mesh(avatar).evaluate_landmarks(points, point_count, output_of(output));
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_evaluate_linear(softdeca_avatar* avatar, const float* weights, uint32_t weight_count,
                                                             const softdeca_output* output) {
  return guarded(__func__, [&] {
    on_mesh(avatar).evaluate_linear(weights, weight_count, output_of(output));
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_set_dynamics(softdeca_avatar* avatar, softdeca_bool enabled) {
  return guarded(__func__, [&] { avatar_of(avatar).set_dynamics(enabled != 0); });
}

SOFTDECA_API softdeca_status softdeca_avatar_reset_dynamics(softdeca_avatar* avatar) {
  return guarded(__func__, [&] { avatar_of(avatar).reset_dynamics(); });
}

SOFTDECA_API softdeca_status softdeca_avatar_get_stats(const softdeca_avatar* avatar, softdeca_stats* out_stats) {
  return guarded(__func__, [&] {
    const Avatar& a = avatar_of(avatar);
    require_struct(out_stats, "out_stats");
    const runtime::AvatarStats s = a.stats();
    out_stats->threads = static_cast<uint32_t>(s.threads);
    out_stats->frames = s.frames;
    out_stats->preparations = s.preparations;
    out_stats->generation = s.generation;
    out_stats->frame_ms = s.frame_ms;
    out_stats->encoder_ms = s.encoder_ms;
    out_stats->blend_ms = s.blend_ms;
    out_stats->hyper_ms = s.hyper_ms;
    out_stats->solve_ms = s.solve_ms;
    out_stats->dynamics_ms = s.dynamics_ms;
    out_stats->output_ms = s.output_ms;
    out_stats->normals_ms = s.normals_ms;
    out_stats->prepare_ms = s.prepare_ms;
    out_stats->prepare_networks_ms = s.prepare_networks_ms;
    out_stats->factorisation_ms = s.factorisation_ms;
    out_stats->memory_bytes = s.memory_bytes + avatar->avatar->bytes();
    out_stats->prepare_physics_ms = s.prepare_physics_ms;
    out_stats->physics_iterations = static_cast<uint32_t>(s.physics_iterations);
    out_stats->reserved = 0;
    out_stats->frame_bytes = s.frame_bytes.total();
  });
}

}  // extern "C"
