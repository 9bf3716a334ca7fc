// Geometry part of the C ABI: thin, checked wrappers over geometry/.
#include <string>

#include "api/error_boundary.h"
#include "geometry/tet_mesh.h"

namespace {
using namespace softdeca;
using namespace softdeca::api;
using geometry::Points;
using geometry::Tets;

Points to_points(const float* xyz, std::size_t count) {
  Points p(static_cast<Eigen::Index>(count), 3);
  for (std::size_t i = 0; i < count * 3; ++i) p.data()[i] = xyz[i];
  return p;
}

Tets checked_tets(const int32_t* tets, std::size_t tet_count, std::size_t vertex_count) {
  Tets t(static_cast<Eigen::Index>(tet_count), 4);
  for (std::size_t i = 0; i < tet_count * 4; ++i) {
    require(tets[i] >= 0 && static_cast<std::size_t>(tets[i]) < vertex_count,
            "tets[" + std::to_string(i) + "] = " + std::to_string(tets[i]) +
                " is not a vertex index below vertex_count = " + std::to_string(vertex_count));
    t.data()[i] = tets[i];
  }
  return t;
}

void check_mesh(const float* vertices, std::size_t vertex_count, const int32_t* tets,
                std::size_t tet_count) {
  require_not_null(vertices, "vertices");
  require_not_null(tets, "tets");
  require(vertex_count >= 4, "vertex_count must be at least 4");
  require(vertex_count < (std::size_t{1} << 30) && tet_count < (std::size_t{1} << 30),
          "vertex_count or tet_count is implausibly large");
  require(tet_count >= 1, "tet_count must be at least 1");
  require_finite(vertices, vertex_count * 3, "vertices");
}
}  // namespace

extern "C" {

SOFTDECA_API softdeca_status softdeca_embed_points(const float* vertices, uint32_t vertex_count,
                                                   const int32_t* tets, uint32_t tet_count,
                                                   const float* points, uint32_t point_count,
                                                   int32_t* out_tet, float* out_barycentric,
                                                   float* out_outside) {
  return guarded(__func__, [&] {
    check_mesh(vertices, vertex_count, tets, tet_count);
    require_not_null(points, "points");
    require_not_null(out_tet, "out_tet");
    require_not_null(out_barycentric, "out_barycentric");
    require(point_count < (std::size_t{1} << 30), "point_count is implausibly large");
    require_finite(points, point_count * 3, "points");
    const auto emb = geometry::embed_points(to_points(vertices, vertex_count),
                                            checked_tets(tets, tet_count, vertex_count),
                                            to_points(points, point_count));
    for (std::size_t i = 0; i < point_count; ++i) {
      out_tet[i] = emb.tet[i];
      for (int k = 0; k < 4; ++k)
        out_barycentric[4 * i + k] = static_cast<float>(emb.bary(static_cast<Eigen::Index>(i), k));
      if (out_outside) out_outside[i] = static_cast<float>(emb.outside[static_cast<Eigen::Index>(i)]);
    }
  });
}

SOFTDECA_API softdeca_status softdeca_compute_tet_volumes(const float* vertices, uint32_t vertex_count,
                                                  const int32_t* tets, uint32_t tet_count,
                                                  float* out_volumes) {
  return guarded(__func__, [&] {
    check_mesh(vertices, vertex_count, tets, tet_count);
    require_not_null(out_volumes, "out_volumes");
    const auto vol = geometry::tet_signed_volumes(to_points(vertices, vertex_count),
                                                  checked_tets(tets, tet_count, vertex_count));
    for (std::size_t i = 0; i < tet_count; ++i) out_volumes[i] = static_cast<float>(vol[static_cast<Eigen::Index>(i)]);
  });
}

}  // extern "C"
