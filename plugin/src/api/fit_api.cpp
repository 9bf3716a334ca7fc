// The fit part of the C ABI: fitting a user's avatar, saving and loading the fit, and the
// avatar made on it (fit/avatar_fit.h, runtime/fitted_avatar.h).
#include <Eigen/LU>
#include <cstring>
#include <string>
#include <vector>

#include "api/error_boundary.h"
#include "api/handles.h"
#include "api/runtime_handles.h"
#include "core/atomic_write.h"
#include "core/regular_file.h"
#include "fit/fit_file.h"
#include "fit/limits.h"
#include "runtime/frame_guard.h"

namespace {
using namespace softdeca;
using namespace softdeca::api;

// A saved fit holds about 30 bytes per avatar vertex and 30 per template skin vertex.
constexpr std::uint64_t kMaxFitFileBytes = std::uint64_t{1} << 30;

fit::FitSizes fit_sizes(const runtime::Model& m) {
  const bundle::Manifest& mf = m.manifest();
  fit::FitSizes s;
  s.head_vertices = static_cast<std::size_t>(mf.head_vertices);
  s.skin_vertices = static_cast<std::size_t>(mf.skin_vertices);
  s.skin_triangles = static_cast<std::size_t>(mf.skin_triangles);
  s.identity_modes = static_cast<std::size_t>(mf.template_identity_modes);
  return s;
}

const softdeca_avatar_fit& fit_of(const softdeca_avatar_fit* f) {
  require_not_null(f, "fit");
  return *f;
}

// The caller's mesh as the fit reads it: a shape that is all zeros is one the rig lacks.
fit::AvatarMesh mesh_of(const softdeca_avatar_mesh* m, const runtime::Model& model) {
  require_struct(m, "mesh");
  require_not_null(m->neutral, "mesh->neutral");
  require(m->vertex_count >= 3 && m->vertex_count <= fit::kMaxAvatarVertices,
          "mesh->vertex_count is " + std::to_string(m->vertex_count) + "; an avatar has 3 to " +
              std::to_string(fit::kMaxAvatarVertices) + " vertices");
  require_not_null(m->triangles, "mesh->triangles");
  require(m->triangle_count >= 1 && m->triangle_count <= fit::kMaxAvatarTriangles, "mesh->triangle_count is out of range");
  require(m->blendshape_count == SOFTDECA_BLENDSHAPE_COUNT,
          "mesh->blendshape_count must be 52 (zeros for a shape the rig lacks), got " + std::to_string(m->blendshape_count));
  require_not_null(m->blendshapes, "mesh->blendshapes");
  const std::size_t n = m->vertex_count;
  fit::AvatarMesh a;
  a.neutral = m->neutral;
  a.vertex_count = n;
  a.triangles = m->triangles;
  a.triangle_count = m->triangle_count;
  for (std::size_t k = 0; k < fit::kShapes; ++k) {
    const float* d = m->blendshapes + k * n * 3;
    for (std::size_t i = 0; i < n * 3; ++i)
      if (d[i] != 0) {
        a.deltas[k] = d;
        break;
      }
  }
  if (m->landmarks) {
    require(m->landmark_count == model.manifest().landmarks.size(),
            "mesh->landmark_count must be the bundle's " + std::to_string(model.manifest().landmarks.size()) + " landmarks");
    require_finite(m->landmarks, std::size_t{m->landmark_count} * 3, "mesh->landmarks");
    a.landmarks = m->landmarks;
    a.landmark_count = m->landmark_count;
  }
  return a;
}
}  // namespace

extern "C" {

SOFTDECA_API softdeca_status softdeca_fit_options_init(softdeca_fit_options* options) {
  return guarded(__func__, [&] {
    require_struct(options, "options");
    reset_struct(options);
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_fit_create(const softdeca_model* model, const softdeca_avatar_mesh* mesh,
                                                        const softdeca_fit_options* options, softdeca_avatar_fit** out_fit) {
  return guarded(__func__, [&] {
    const runtime::Model& m = model_of(model);
    require_not_null(out_fit, "out_fit");
    const fit::AvatarMesh a = mesh_of(mesh, m);
    fit::FitOptions o;
    if (options) {
      require_struct(options, "options");
      const double unit = options->metres_per_unit;
      require(unit == 0 || (unit >= fit::kMinMetresPerUnit && unit <= fit::kMaxMetresPerUnit),
              "options->metres_per_unit must be 0 (detect) or a unit of " + fit::metres_per_unit_range() + " m");
      require(options->iterations <= 1000, "options->iterations must be at most 1000");
      o.metres_per_unit = options->metres_per_unit;
      o.iterations = static_cast<int>(options->iterations);
    }
    const fit::TemplateData t = runtime::fit_template(m);
    create_handle(out_fit, "out_fit", [&](softdeca_avatar_fit& h) {
      h.fit = fit::fit_avatar(t, a, o);
      h.bundle_sha256 = m.manifest_sha256();
      // What is saved must load: a fit outside the ranges the loader accepts is not made.
      const std::string problem = fit::fit_out_of_range(h.fit, fit_sizes(m));
      require(problem.empty(), "the avatar gives a fit outside the ranges a fit lies in (" + problem + ")");
    });
  });
}

SOFTDECA_API void softdeca_avatar_fit_destroy(softdeca_avatar_fit* fit) { destroy_handle(__func__, fit); }

SOFTDECA_API softdeca_status softdeca_avatar_fit_save(const softdeca_avatar_fit* fit, const char* path) {
  return guarded(__func__, [&] {
    const softdeca_avatar_fit& f = fit_of(fit);
    require_not_null(path, "path");
    const std::vector<std::uint8_t> bytes = fit::encode_fit(f.fit, f.bundle_sha256, f.fit.source.weight.size());
    write_file_atomically(path, bytes.data(), bytes.size());
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_fit_load(const softdeca_model* model, const char* path,
                                                      softdeca_avatar_fit** out_fit) {
  return guarded(__func__, [&] {
    const runtime::Model& m = model_of(model);
    require_not_null(path, "path");
    require_not_null(out_fit, "out_fit");
    FilePtr file = open_regular_file(path, FileAccess::read);
    const std::uint64_t size = file_size(file.get());
    if (size > kMaxFitFileBytes) throw Error(SOFTDECA_ERROR_FORMAT, std::string(path) + " is larger than any fit");
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
    if (!read_at(file.get(), 0, bytes.data(), bytes.size())) throw Error(SOFTDECA_ERROR_IO, std::string("could not read ") + path);
    create_handle(out_fit, "out_fit", [&](softdeca_avatar_fit& h) {
      h.fit = fit::decode_fit(bytes.data(), bytes.size(), path, m.manifest_sha256(), fit_sizes(m));
      h.bundle_sha256 = m.manifest_sha256();
    });
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_fit_get_report(const softdeca_avatar_fit* fit, char* buffer, uint32_t capacity,
                                                        uint32_t* out_length) {
  return guarded(__func__, [&] {
    const std::string& r = fit_of(fit).fit.report;
    if (out_length) *out_length = static_cast<uint32_t>(r.size());
    if (capacity < r.size() + 1)
      throw Error(SOFTDECA_ERROR_BUFFER_TOO_SMALL,
                  "the report needs " + std::to_string(r.size() + 1) + " bytes, the buffer has " + std::to_string(capacity));
    require_not_null(buffer, "buffer");
    std::memcpy(buffer, r.c_str(), r.size() + 1);
  });
}

SOFTDECA_API softdeca_status softdeca_avatar_fit_get_registered(const softdeca_avatar_fit* fit, float* out_points,
                                                                uint32_t point_capacity, uint32_t* out_vertex_count) {
  return guarded(__func__, [&] {
    const fit::AvatarFit& f = fit_of(fit).fit;
    const std::size_t vs = f.source.weight.size();
    if (out_points) {
      expect(point_capacity >= vs, [&] {
        return "point_capacity " + std::to_string(point_capacity) + " is below the skin's " + std::to_string(vs) + " points";
      }, SOFTDECA_ERROR_BUFFER_TOO_SMALL);
      const Eigen::Matrix3d inv = f.placement.linear.inverse();
      for (std::size_t v = 0; v < vs; ++v) {
        const Eigen::Vector3d x(f.registered[3 * v], f.registered[3 * v + 1], f.registered[3 * v + 2]);
        const Eigen::Vector3d p = inv * (x - f.placement.offset);
        for (int c = 0; c < 3; ++c) out_points[3 * v + static_cast<std::size_t>(c)] = static_cast<float>(p[c]);
      }
    }
    if (out_vertex_count) *out_vertex_count = static_cast<uint32_t>(f.vertex_count);
  });
}

}  // extern "C"

namespace softdeca::api {

namespace {
// A mesh in the template's topology, checked as the template path takes it (shapes optional).
runtime::AvatarDesc template_mesh(const softdeca_avatar_mesh* mesh, const runtime::Model& m) {
  require_struct(mesh, "desc->mesh");
  const std::size_t vh = static_cast<std::size_t>(m.manifest().head_vertices);
  require_not_null(mesh->neutral, "desc->mesh->neutral");
  require(mesh->vertex_count == vh, "desc->mesh->vertex_count is " + std::to_string(mesh->vertex_count) +
                                        "; the bundle's template has " + std::to_string(vh) +
                                        " head vertices (another mesh needs its fit in desc->fit)");
  require_finite(mesh->neutral, vh * 3, "desc->mesh->neutral");
  require_not_null(mesh->triangles, "desc->mesh->triangles");
  require(mesh->triangle_count >= 1 && mesh->triangle_count < (std::size_t{1} << 28), "desc->mesh->triangle_count is out of range");
  for (std::size_t i = 0; i < mesh->triangle_count * 3; ++i)
    require(mesh->triangles[i] >= 0 && static_cast<std::size_t>(mesh->triangles[i]) < vh,
            "desc->mesh->triangles[" + std::to_string(i) + "] = " + std::to_string(mesh->triangles[i]) + " is not a vertex index");
  require(mesh->blendshape_count == 0 || mesh->blendshape_count == bundle::kBlendshapeCount,
          "desc->mesh->blendshape_count must be 0 or 52");
  if (mesh->blendshape_count) {
    require_not_null(mesh->blendshapes, "desc->mesh->blendshapes");
    require_finite(mesh->blendshapes, bundle::kBlendshapeCount * vh * 3, "desc->mesh->blendshapes");
  }
  runtime::AvatarDesc d;
  d.neutral = mesh->neutral;
  d.vertex_count = vh;
  d.triangles = mesh->triangles;
  d.triangle_count = mesh->triangle_count;
  d.blendshapes = mesh->blendshape_count ? mesh->blendshapes : nullptr;
  d.blendshape_count = mesh->blendshape_count;
  return d;
}
}  // namespace

std::unique_ptr<runtime::FittedAvatar> avatar_on_mesh(const softdeca_model* model, const softdeca_avatar_mesh* mesh,
                                                      const softdeca_avatar_fit* fit, std::size_t threads,
                                                      const runtime::Precisions& precisions) {
  const runtime::Model& m = model_of(model);
  if (!fit) {  // the identity fit
    runtime::AvatarDesc d = template_mesh(mesh, m);
    d.threads = threads;
    d.precisions = precisions;
    return std::make_unique<runtime::FittedAvatar>(model->model, d);
  }
  const softdeca_avatar_fit& f = fit_of(fit);
  require(f.bundle_sha256 == m.manifest_sha256(), "the fit was made for another bundle: fit the avatar again with this one");
  const fit::AvatarMesh a = mesh_of(mesh, m);
  runtime::FittedAvatarDesc d;
  d.fit = &f.fit;
  d.mesh = &a;
  d.threads = threads;
  d.precisions = precisions;
  return std::make_unique<runtime::FittedAvatar>(model->model, d);
}

}  // namespace softdeca::api
