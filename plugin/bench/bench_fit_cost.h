// bench-reliability's fit runs: what fitting an avatar costs in time and memory as the mesh
// grows, and on a head with thousands of sliver triangles added (docs/security.md, "Avatar
// files"). The avatars are made from a small one: subdivided (every triangle into four, the
// shapes interpolated) to the size asked, or given long thin triangles between random vertices.
// Each fit runs in a child process, so that its peak memory is its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "imported_avatar.h"

namespace softdeca::cli {

// The bytes of the arrays the fit is given (neutral, triangles, shapes).
std::uint64_t mesh_bytes(const AvatarFile& a);

// Every triangle split into four at its edges' midpoints (positions and shapes interpolated)
// until the mesh has at least `vertices` vertices; only the arrays are kept.
AvatarFile subdivided(AvatarFile a, std::size_t vertices);

// `count` long thin triangles added, each from a random edge of the mesh to a random vertex.
AvatarFile with_slivers(AvatarFile a, std::size_t count, unsigned seed);

struct FitRun {
  bool fitted = false;
  std::string error;                // the refusal, when not fitted
  double seconds = 0;               // softdeca_avatar_fit_create, wall clock
  double cpu_seconds = 0;           // the same, the process's CPU time (the fit runs on one thread)
  std::uint64_t peak_increase = 0;  // the child's peak RSS over its RSS before the fit
};

// Loads `bundle` in a child process and fits `a` there at `metres_per_unit` (0: read off the
// shapes). Throws std::runtime_error when the child dies.
FitRun fit_in_child(const std::string& bundle, const AvatarFile& a, double metres_per_unit);

struct FitCost {
  std::size_t vertices = 0, base_vertices = 0, slivers = 0;
  FitRun large, sliver;
  std::uint64_t large_input_bytes = 0;
  double seconds_per_100k() const { return large.seconds / (double(vertices) / 1e5); }
  // The large fit's peak memory (the mesh and the fit's own increase) over 4x the mesh + 500 MB.
  double memory_over_target() const;
  // What the runs did, for the figures' "how".
  std::string describe(const std::string& avatar, const std::string& bundle) const;
};

// The avatar at `avatar` (any file the command line reads) subdivided to `vertices` and fitted
// by `bundle` at `metres_per_unit` (0: read off the shapes); then with 20,000 slivers. Throws
// when the large avatar is not fitted.
FitCost fit_cost_run(const std::string& bundle, const std::string& avatar, std::size_t vertices, double metres_per_unit);

}  // namespace softdeca::cli
