#include "bench_fit_cost.h"

#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <unordered_map>

#include "bench_child_memory.h"

namespace softdeca::cli {

std::uint64_t mesh_bytes(const AvatarFile& a) {
  return (a.neutral.size() + a.blendshapes.size()) * sizeof(float) + a.triangles.size() * sizeof(std::int32_t);
}

namespace {
double cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// One level of subdivision: a vertex at every edge's midpoint, four triangles for each.
AvatarFile split_once(const AvatarFile& a) {
  const std::size_t n = a.vertex_count();
  std::unordered_map<std::uint64_t, std::int32_t> midpoint;
  midpoint.reserve(a.triangles.size());
  std::vector<std::pair<std::int32_t, std::int32_t>> ends;
  const auto middle = [&](std::int32_t u, std::int32_t v) {
    const std::uint64_t key = (std::uint64_t(std::uint32_t(std::min(u, v))) << 32) | std::uint32_t(std::max(u, v));
    const auto [it, added] = midpoint.emplace(key, static_cast<std::int32_t>(n + ends.size()));
    if (added) ends.emplace_back(u, v);
    return it->second;
  };
  AvatarFile out;
  out.triangles.reserve(4 * a.triangles.size());
  for (std::size_t t = 0; t < a.triangles.size() / 3; ++t) {
    const std::int32_t* c = a.triangles.data() + 3 * t;
    const std::int32_t ab = middle(c[0], c[1]), bc = middle(c[1], c[2]), ca = middle(c[2], c[0]);
    out.triangles.insert(out.triangles.end(), {c[0], ab, ca, ab, c[1], bc, ca, bc, c[2], ab, bc, ca});
  }
  const std::size_t total = n + ends.size();
  const auto fill = [&](const float* from, float* to) {
    std::copy(from, from + 3 * n, to);
    for (std::size_t e = 0; e < ends.size(); ++e)
      for (std::size_t k = 0; k < 3; ++k)
        to[3 * (n + e) + k] = 0.5f * (from[3 * std::size_t(ends[e].first) + k] + from[3 * std::size_t(ends[e].second) + k]);
  };
  out.neutral.resize(3 * total);
  fill(a.neutral.data(), out.neutral.data());
  out.blendshapes.resize(52 * 3 * total);
  for (std::size_t s = 0; s < 52; ++s) fill(a.blendshapes.data() + s * 3 * n, out.blendshapes.data() + s * 3 * total);
  return out;
}
}  // namespace

AvatarFile subdivided(AvatarFile a, std::size_t vertices) {
  while (a.vertex_count() < vertices && !a.triangles.empty()) a = split_once(a);
  return a;
}

AvatarFile with_slivers(AvatarFile a, std::size_t count, unsigned seed) {
  std::mt19937 random(seed);
  const std::size_t triangles = a.triangles.size() / 3;
  std::uniform_int_distribution<std::size_t> any_triangle(0, triangles - 1), any_corner(0, 2);
  std::uniform_int_distribution<std::int32_t> any_vertex(0, static_cast<std::int32_t>(a.vertex_count()) - 1);
  for (std::size_t i = 0; i < count; ++i) {
    const std::int32_t* t = a.triangles.data() + 3 * any_triangle(random);
    const std::size_t k = any_corner(random);
    a.triangles.insert(a.triangles.end(), {t[k], t[(k + 1) % 3], any_vertex(random)});
  }
  return a;
}

FitRun fit_in_child(const std::string& bundle, const AvatarFile& a, double metres_per_unit) {
  softdeca_model* model = nullptr;  // the child's
  const auto load = [&]() -> std::string {
    if (softdeca_model_load(bundle.c_str(), nullptr, &model) == SOFTDECA_OK) return "";
    return "cannot load " + bundle + ": " + softdeca_last_error();
  };
  // "<1 fitted, 0 refused> <seconds> <cpu seconds> <the refusal>"
  const auto fit = [&]() -> std::string {
    softdeca_fit_options options{};
    options.struct_size = sizeof options;
    softdeca_fit_options_init(&options);
    options.metres_per_unit = metres_per_unit;
    const softdeca_avatar_mesh mesh = a.abi_mesh();
    softdeca_avatar_fit* made = nullptr;
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = cpu_seconds();
    const softdeca_status status = softdeca_avatar_fit_create(model, &mesh, &options, &made);
    const double cpu = cpu_seconds() - cpu0;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    char head[96];
    std::snprintf(head, sizeof head, "%d %.6f %.6f ", status == SOFTDECA_OK ? 1 : 0, seconds, cpu);
    const std::string report = head + std::string(status == SOFTDECA_OK ? "" : softdeca_last_error());
    softdeca_avatar_fit_destroy(made);
    return report;
  };
  const ChildPeak c = peak_in_child("fitting " + std::to_string(a.vertex_count()) + " vertices", load, fit);
  if (!c.prepared) throw std::runtime_error("bench-reliability: " + c.report);
  FitRun out;
  char* rest = nullptr;
  out.fitted = std::strtol(c.report.c_str(), &rest, 10) == 1;
  out.seconds = std::strtod(rest, &rest);
  out.cpu_seconds = std::strtod(rest, &rest);
  out.peak_increase = c.increase;
  if (*rest == ' ') out.error = rest + 1;
  return out;
}

double FitCost::memory_over_target() const {
  const double input = double(large_input_bytes);
  return (input + double(large.peak_increase)) / (4 * input + 500e6);
}

std::string FitCost::describe(const std::string& avatar, const std::string& bundle) const {
  char text[900];
  std::snprintf(text, sizeof text,
                "%s (%zu vertices) subdivided to %zu vertices (%.0f MB of mesh), fitted by %s in a child process: "
                "%.1f s, the fit's peak RSS increase %.0f MB; the mesh and that increase over 4x the mesh + 500 MB: "
                "%.2f. The same avatar with %zu sliver triangles (an edge of it to a random vertex) added: %s in %.1f s%s%s",
                avatar.c_str(), base_vertices, vertices, double(large_input_bytes) / 1e6, bundle.c_str(), large.seconds,
                double(large.peak_increase) / 1e6, memory_over_target(), slivers, sliver.fitted ? "fitted" : "refused",
                sliver.seconds, sliver.fitted ? "" : ": ", sliver.error.c_str());
  return text;
}

FitCost fit_cost_run(const std::string& bundle, const std::string& avatar, std::size_t vertices, double metres_per_unit) {
  const AvatarFile base = read_avatar_file(avatar);
  FitCost out;
  out.base_vertices = base.vertex_count();
  {
    const AvatarFile large = subdivided(base, vertices);
    out.vertices = large.vertex_count();
    out.large_input_bytes = mesh_bytes(large);
    out.large = fit_in_child(bundle, large, metres_per_unit);
  }
  if (!out.large.fitted)
    throw std::runtime_error("bench-reliability: the subdivided avatar was not fitted: " + out.large.error);
  out.slivers = 20000;
  out.sliver = fit_in_child(bundle, with_slivers(base, out.slivers, 7), metres_per_unit);
  return out;
}

}  // namespace softdeca::cli
