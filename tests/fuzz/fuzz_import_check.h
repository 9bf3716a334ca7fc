// The properties every avatar the import layer hands over must have, whatever file it came
// from: what a reader returns is sized consistently and its triangles name its own vertices;
// what assemble_avatar returns is what the C ABI takes (finite after placing, 52 shapes, within
// the limits, shapes nobody gives left at zero).
#pragma once

#include <cmath>
#include <cstddef>

#include "avatar_file.h"
#include "avatar_source.h"
#include "fuzz_check.h"

namespace softdeca::fuzz {

inline void check_scene(const avatar_import::SourceScene& scene, const avatar_import::ImportLimits& limits) {
  for (const avatar_import::SourceMesh& mesh : scene.meshes) {
    FUZZ_CHECK(mesh.vertices.size() % 3 == 0 && mesh.triangles.size() % 3 == 0);
    FUZZ_CHECK(mesh.vertex_count() <= limits.max_vertices);
    for (const std::int32_t t : mesh.triangles) FUZZ_CHECK(t >= 0 && static_cast<std::size_t>(t) < mesh.vertex_count());
    for (const avatar_import::SourceShape& shape : mesh.shapes) FUZZ_CHECK(shape.deltas.size() % 3 == 0);
  }
}

inline void check_avatar(const avatar_import::AvatarFile& avatar, const avatar_import::ImportLimits& limits) {
  const std::size_t n = avatar.vertex_count();
  FUZZ_CHECK(n > 0 && n <= limits.max_vertices && avatar.neutral.size() == 3 * n);
  FUZZ_CHECK(avatar.blendshapes.size() == 52 * 3 * n);
  FUZZ_CHECK(avatar.triangles.size() % 3 == 0 && !avatar.triangles.empty());
  FUZZ_CHECK(avatar.shape_count() >= 1 && !avatar.parts.empty());
  for (const std::int32_t t : avatar.triangles) FUZZ_CHECK(t >= 0 && static_cast<std::size_t>(t) < n);
  for (const float v : avatar.neutral) FUZZ_CHECK(std::isfinite(v));
  for (const float v : avatar.blendshapes) FUZZ_CHECK(std::isfinite(v));
  std::size_t covered = 0;
  for (const avatar_import::AvatarPart& part : avatar.parts) {
    FUZZ_CHECK(part.first_vertex == covered);
    covered += part.vertex_count;
  }
  FUZZ_CHECK(covered == n);
  for (std::size_t k = 0; k < 52; ++k) {
    if (!avatar.shape_sources[k].empty()) continue;  // a shape nobody gives moves nothing
    for (std::size_t i = 0; i < 3 * n; ++i) FUZZ_CHECK(avatar.blendshapes[3 * k * n + i] == 0.0f);
  }
}

}  // namespace softdeca::fuzz
