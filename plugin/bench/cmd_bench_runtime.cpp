// softdeca bench-runtime: per-frame cost of the runtime on one avatar, measured on the frames of
// a real take: plain linear blendshapes, SoftDECA static and dynamic, SparseSoftDECA, with one
// and with two threads; prepare time, memory per avatar, and the error the compact hyper-tensor
// storage adds (half and int8 against float, same frames), what the C ABI's handle adds to the
// template's frame over the core avatar it holds, and the shipped bundle's frames (at the
// library's default precisions, as users run it) and the random bundle's deformation-transfer
// frames against the machine's memory bandwidth. Writes the benchmark JSON of
// docs/ARCHITECTURE.md, Conventions ({figure: {value, unit, target, better, how}}).
// Kept whole: every figure is measured in one run on the same inputs (take, avatars, bundles),
// so their ratios hold; each figure's measurement is a function of its own.
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "bench_bandwidth.h"
#include "bench_core_avatar.h"
#include "bench_figures.h"
#include "command.h"
#include "imported_avatar.h"
#include "json.h"
#include "options.h"
#include "runtime_session.h"
#include "take.h"

namespace softdeca::cli {

namespace {
using Clock = std::chrono::steady_clock;

constexpr double kPaperStaticMs = 7.45, kPaperDynamicMs = 9.87, kPaperFaces = 71358;

// The random bundle's figures: both models' tables in half, as those figures have always been
// measured (the shipped bundle's run at the library's defaults instead).
constexpr AvatarPrecisions kHalf{SOFTDECA_PRECISION_HALF, SOFTDECA_PRECISION_HALF};
// Both models' tables at one precision.
AvatarPrecisions both(int32_t precision) { return {precision, precision}; }

// The shared figure (bench_figures.h) with this command's argument order: most figures have no target.
std::string figure(double value, const std::string& unit, const std::string& how, double target = NAN,
                   const char* better = "lower") {
  return cli::figure(value, unit.c_str(), std::isfinite(target) ? json_number(target) : "null", better, how);
}

std::string cpu_name() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

struct Frames {
  const Take& take;
  std::vector<std::vector<float>> points;  // per frame: what SparseSoftDECA reads
  std::size_t point_count = 0;
};

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

// Medians over the frames after `warmup`: wall-clock time, and the calling thread's CPU time
// (what a frame costs when the machine is not shared: preemption by other processes is not in
// it; with helper threads only the caller's share is).
struct Times {
  double wall = 0, cpu = 0;
};
template <class F>
Times median_ms(std::size_t frames, std::size_t warmup, F&& call) {
  std::vector<double> wall, cpu;
  for (std::size_t i = 0; i < warmup + frames; ++i) {
    const auto t0 = Clock::now();
    const double c0 = thread_cpu_ms();
    call(i % frames);
    const double c1 = thread_cpu_ms();
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (i >= warmup) {
      wall.push_back(ms);
      cpu.push_back(c1 - c0);
    }
  }
  return {median(wall), median(cpu)};
}

// What every measurement reads: the take, the rigs, the bundle, the frames' SparseSoftDECA input,
// the output buffers and the description recorded with each figure.
struct Bench {
  const Take& take;
  const FaceRig& rig;
  const FaceRig& user;
  Model& model;
  std::size_t frames = 0, warmup = 0;
  long prepares = 0;
  std::string how;
  Frames input;
  std::vector<float> vertices, normals;
  softdeca_output output{};
  JsonObject figures;
  std::string out_dir;  // where the benchmark JSON goes (scratch files beside it)
  double copy_read_gb_s = 0;  // measured once, by the first bandwidth share (0: not yet)
};

// What SparseSoftDECA reads each frame: the user rig's face mesh, or the avatar's own landmarks.
Frames sparse_inputs(const Take& take, std::size_t frames, const FaceRig& rig, const FaceRig& user, Model& model) {
  const uint32_t vh = model.info.head_vertex_count;
  Frames input{take, {}, 0};
  Avatar a(model, rig.neutral, rig.deltas, 1);  // its linear blend only
  std::vector<float> head(vh * 3);
  softdeca_output out{sizeof(softdeca_output), head.data(), vh, nullptr, 0};
  for (std::size_t f = 0; f < frames; ++f) {
    if (!user.empty()) {
      std::vector<float> p(user.neutral.vertices.size());
      user.blend(take.weights[f].data(), p.data());
      input.points.push_back(std::move(p));
      input.point_count = user.neutral.vertex_count();
    } else {
      check(softdeca_avatar_evaluate_linear(a.handle, take.weights[f].data(), 52, &out), "linear");
      std::vector<float> p(3 * model.info.landmark_count);
      check(softdeca_model_evaluate_landmarks(model.handle, head.data(), vh, p.data(), model.info.landmark_count), "landmarks");
      input.points.push_back(std::move(p));
      input.point_count = model.info.landmark_count;
    }
  }
  return input;
}

// Prepare time, memory per avatar and the cost of a frame relative to the paper (1 thread only).
void record_prepare_and_memory(Bench& bench, const Avatar& a, const softdeca_stats& first, const std::vector<double>& prep,
                               double static_ms) {
  const std::string& how = bench.how;
  bench.figures.raw("runtime.prepare_ms", figure(median(prep), "ms", "prepare after a parameter change: f_ph, f_ph_v, both f_dyn, "
                                                                     "compact hyper-tensors; median of " +
                                                                         std::to_string(prep.size()) + "; " + how));
  bench.figures.raw("runtime.first_prepare_ms",
                    figure(first.prepare_ms, "ms", "the first prepare, including the DT assembly and factorisation (" +
                                                       std::to_string(first.factorisation_ms) + " ms); " + how));
  bench.figures.raw("runtime.memory_per_avatar_mb",
                    figure(static_cast<double>(a.stats().memory_bytes) / 1e6, "MB",
                           "softdeca_stats.memory_bytes after prepare (both models' hyper-tensors in half precision, DT "
                           "factor, blendshapes, buffers); " + how));
  bench.figures.raw("runtime.softdeca_static_us_per_face",
                    figure(static_ms * 1000.0 / bench.model.info.skin_triangle_count, "us/face",
                           "softdeca_static_ms per skin triangle; paper: " + std::to_string(kPaperStaticMs * 1000 / kPaperFaces) +
                               " us/face static, " + std::to_string(kPaperDynamicMs * 1000 / kPaperFaces) +
                               " dynamic (7.45 / 9.87 ms for 71,358 faces, i5-12600K, PyTorch)"));
}

// The physics at prepare (bundles with rest physics): the first prepare away from the defaults
// (carrying the tissue fill, the contact sets, the defaults' solve and p's) and later prepares
// after a gravity change (p's solve only) and after a soft-tissue weight change (refactorised).
void measure_rest_physics(Bench& bench) {
  Avatar a(bench.model, bench.rig.neutral, bench.rig.deltas, 1, kHalf);
  check(softdeca_avatar_prepare(a.handle), "prepare");
  const auto gravity = static_cast<uint32_t>(bench.model.parameter("gravity_strength"));
  const auto soft = static_cast<uint32_t>(bench.model.parameter("w_soft_strain"));
  check(softdeca_avatar_set_parameter(a.handle, gravity, 2.0), "gravity");
  check(softdeca_avatar_prepare(a.handle), "prepare");
  const softdeca_stats first = a.stats();
  if (first.prepare_physics_ms == 0) return;  // the bundle has no rest physics
  std::vector<double> by_gravity, by_tissue;
  for (long i = 0; i < bench.prepares; ++i) {
    check(softdeca_avatar_set_parameter(a.handle, gravity, i % 2 ? 2.0 : 1.5), "gravity");
    check(softdeca_avatar_prepare(a.handle), "prepare");
    by_gravity.push_back(a.stats().prepare_physics_ms);
    check(softdeca_avatar_set_parameter(a.handle, soft, i % 2 ? 5.0 : 2.0), "soft strain");
    check(softdeca_avatar_prepare(a.handle), "prepare");
    by_tissue.push_back(a.stats().prepare_physics_ms);
  }
  // A frame with the rest offset against one at the defaults, alternately on two avatars.
  Avatar plain(bench.model, bench.rig.neutral, bench.rig.deltas, 1, kHalf);
  check(softdeca_avatar_prepare(plain.handle), "prepare");
  const auto w = [&](std::size_t f) { return bench.take.weights[f].data(); };
  Times with{}, without{};
  for (int round = 0; round < 2; ++round) {
    const Times x = median_ms(bench.frames, bench.warmup, [&](std::size_t f) {
      check(softdeca_avatar_evaluate_weights(a.handle, w(f), 52, &bench.output), "softdeca");
    });
    const Times y = median_ms(bench.frames, bench.warmup, [&](std::size_t f) {
      check(softdeca_avatar_evaluate_weights(plain.handle, w(f), 52, &bench.output), "softdeca");
    });
    with.wall += x.wall / 2, with.cpu += x.cpu / 2, without.wall += y.wall / 2, without.cpu += y.cpu / 2;
  }
  const std::string how = "; 1 thread; " + bench.how;
  bench.figures.raw("runtime.softdeca_static_ms_rest_physics",
                    figure(with.cpu, "ms", "as softdeca_static_cpu_ms (thread CPU time) with the rest offset of a gravity "
                                           "change added; the same avatar at the defaults, alternately: " +
                                               std::to_string(without.cpu) + " ms" + how));
  bench.figures.raw("runtime.prepare_physics_first_ms",
                    figure(first.prepare_ms, "ms", "the first prepare away from the defaults (gravity 2 g): the tissue fill "
                                                   "carried to the avatar, its contact sets, the physics at rest under the "
                                                   "defaults and under p (" + std::to_string(first.prepare_physics_ms) +
                                                   " ms of it)" + how));
  bench.figures.raw("runtime.prepare_physics_gravity_ms",
                    figure(median(by_gravity), "ms", "the physics at rest of a prepare after a gravity change (no "
                                                     "refactorisation); median of " + std::to_string(by_gravity.size()) + how));
  bench.figures.raw("runtime.prepare_physics_tissue_ms",
                    figure(median(by_tissue), "ms", "the physics at rest of a prepare after a soft-tissue weight change "
                                                    "(refactorised); median of " + std::to_string(by_tissue.size()) + how));
}

// Every model per frame with half-precision hyper-tensors on `threads` threads.
void measure_with_threads(Bench& bench, unsigned threads) {
  const std::string suffix = threads == 1 ? "" : "_2threads";
  const std::string tag = threads == 1 ? " (1 thread)" : " (2 threads)";
  Avatar a(bench.model, bench.rig.neutral, bench.rig.deltas, threads, kHalf);
  check(softdeca_avatar_prepare(a.handle), "prepare");
  const softdeca_stats first = a.stats();
  std::vector<double> prep;
  for (long i = 0; i < bench.prepares; ++i) {
    check(softdeca_avatar_prepare(a.handle), "prepare");
    prep.push_back(a.stats().prepare_ms);
  }
  if (!bench.user.empty())
    check(softdeca_avatar_calibrate_landmarks(a.handle, bench.user.neutral.vertices.data(), bench.user.neutral.vertex_count()),
          "calibration");
  const auto w = [&](std::size_t f) { return bench.take.weights[f].data(); };
  softdeca_output* output = &bench.output;
  const Frames& input = bench.input;
  const std::size_t frames = bench.frames, warmup = bench.warmup;
  const double load_before = load_average();
  const Times lin = median_ms(frames, warmup, [&](std::size_t f) {
    check(softdeca_avatar_evaluate_linear(a.handle, w(f), 52, output), "linear");
  });
  check(softdeca_avatar_set_dynamics(a.handle, SOFTDECA_FALSE), "dynamics");
  const Times st = median_ms(frames, warmup, [&](std::size_t f) {
    check(softdeca_avatar_evaluate_weights(a.handle, w(f), 52, output), "softdeca");
  });
  check(softdeca_avatar_set_dynamics(a.handle, SOFTDECA_TRUE), "dynamics");
  const Times dy = median_ms(frames, warmup, [&](std::size_t f) {
    check(softdeca_avatar_evaluate_weights(a.handle, w(f), 52, output), "softdeca");
  });
  const Times sp = median_ms(frames, warmup, [&](std::size_t f) {
    check(softdeca_avatar_evaluate_landmarks(a.handle, input.points[f].data(), input.point_count, output), "sparse");
  });
  check(softdeca_avatar_set_dynamics(a.handle, SOFTDECA_FALSE), "dynamics");
  const Times sp_static = median_ms(frames, warmup, [&](std::size_t f) {
    check(softdeca_avatar_evaluate_landmarks(a.handle, input.points[f].data(), input.point_count, output), "sparse");
  });
  const double load = std::max(load_before, load_average());
  char load_text[96];
  std::snprintf(load_text, sizeof load_text, "; machine load average %.1f during the run", load);
  const std::string when = tag + "; " + bench.how + load_text;
  JsonObject& figures = bench.figures;
  figures.raw("runtime.softdeca_static_ms" + suffix, figure(st.wall, "ms", "evaluate_weights, dynamics off, with normals, wall-clock" + when, 2.0));
  figures.raw("runtime.softdeca_dynamic_ms" + suffix, figure(dy.wall, "ms", "evaluate_weights, dynamics on, with normals, wall-clock" + when, 2.0));
  figures.raw("runtime.sparse_ms" + suffix, figure(sp.wall, "ms", "evaluate_landmarks, dynamics on, with normals, wall-clock" + when, 0.5));
  figures.raw("runtime.sparse_static_ms" + suffix, figure(sp_static.wall, "ms", "evaluate_landmarks, dynamics off, wall-clock" + when, 0.5));
  figures.raw("runtime.linear_blendshapes_ms" + suffix,
              figure(lin.wall, "ms", "evaluate_linear: 52 sparse blendshapes over the whole head, with normals, wall-clock" + when));
  figures.raw("runtime.softdeca_over_linear" + suffix,
              figure(st.wall / lin.wall, "x", "softdeca_static_ms / linear_blendshapes_ms, same avatar, same run" + tag, 3.0));
  if (threads == 1) {  // CPU time of the frame thread: the cost without other processes
    figures.raw("runtime.softdeca_static_cpu_ms", figure(st.cpu, "ms", "as softdeca_static_ms, thread CPU time" + when, 2.0));
    figures.raw("runtime.softdeca_dynamic_cpu_ms", figure(dy.cpu, "ms", "as softdeca_dynamic_ms, thread CPU time" + when, 2.0));
    figures.raw("runtime.sparse_cpu_ms", figure(sp.cpu, "ms", "as sparse_ms, thread CPU time" + when, 0.5));
    figures.raw("runtime.linear_blendshapes_cpu_ms", figure(lin.cpu, "ms", "as linear_blendshapes_ms, thread CPU time" + when));
    figures.raw("runtime.softdeca_over_linear_cpu",
                figure(st.cpu / lin.cpu, "x", "softdeca_static_cpu_ms / linear_blendshapes_cpu_ms" + tag, 3.0));
  }
  std::fprintf(stderr,
               "%u thread(s), load %.1f: wall linear %.3f  softdeca %.3f / dynamic %.3f  sparse %.3f / static %.3f ms (x%.2f); "
               "cpu linear %.3f softdeca %.3f / %.3f sparse %.3f ms\n",
               threads, load, lin.wall, st.wall, dy.wall, sp.wall, sp_static.wall, st.wall / lin.wall, lin.cpu, st.cpu, dy.cpu,
               sp.cpu);
  if (threads == 1) record_prepare_and_memory(bench, a, first, prep, st.wall);
}

// The speed of another hyper-tensor storage, single thread (same frames, same run).
void measure_storage(Bench& bench, int32_t precision) {
  const char* name = precision == SOFTDECA_PRECISION_INT8 ? "int8" : "float";
  Avatar a(bench.model, bench.rig.neutral, bench.rig.deltas, 1, both(precision));
  check(softdeca_avatar_prepare(a.handle), "prepare");
  const auto w = [&](std::size_t f) { return bench.take.weights[f].data(); };
  softdeca_output* output = &bench.output;
  const Times lin = median_ms(bench.frames, bench.warmup, [&](std::size_t f) {
    check(softdeca_avatar_evaluate_linear(a.handle, w(f), 52, output), "linear");
  });
  const Times st = median_ms(bench.frames, bench.warmup, [&](std::size_t f) {
    check(softdeca_avatar_evaluate_weights(a.handle, w(f), 52, output), "softdeca");
  });
  check(softdeca_avatar_set_dynamics(a.handle, SOFTDECA_TRUE), "dynamics");
  const Times dy = median_ms(bench.frames, bench.warmup, [&](std::size_t f) {
    check(softdeca_avatar_evaluate_weights(a.handle, w(f), 52, output), "softdeca");
  });
  char load_text[64];
  std::snprintf(load_text, sizeof load_text, "; machine load average %.1f", load_average());
  const std::string& how = bench.how;
  JsonObject& figures = bench.figures;
  figures.raw(std::string("runtime.softdeca_static_ms_") + name,
              figure(st.wall, "ms", std::string("as softdeca_static_ms with ") + name + " hyper-tensors (1 thread); " + how + load_text));
  figures.raw(std::string("runtime.softdeca_static_cpu_ms_") + name,
              figure(st.cpu, "ms", std::string("as softdeca_static_cpu_ms with ") + name + " hyper-tensors; " + how + load_text));
  figures.raw(std::string("runtime.softdeca_dynamic_ms_") + name,
              figure(dy.wall, "ms", std::string("as softdeca_dynamic_ms with ") + name + " hyper-tensors (1 thread); " + how + load_text));
  figures.raw(std::string("runtime.softdeca_over_linear_") + name,
              figure(st.wall / lin.wall, "x", std::string("softdeca_static_ms_") + name + " / linear_blendshapes_ms measured just before on "
                                              "the same avatar (1 thread); " + how + load_text, 3.0));
  figures.raw(std::string("runtime.softdeca_over_linear_cpu_") + name,
              figure(st.cpu / lin.cpu, "x", std::string("the same in thread CPU time; ") + how + load_text, 3.0));
  std::fprintf(stderr, "%s storage: wall linear %.3f softdeca %.3f / dynamic %.3f ms (x%.2f); cpu linear %.3f softdeca %.3f ms (x%.2f)\n",
               name, lin.wall, st.wall, dy.wall, st.wall / lin.wall, lin.cpu, st.cpu, st.cpu / lin.cpu);
}

// Error of the compact storage: the same frames with float, half and int8 hyper-tensors, on
// `model` (keys `runtime.<prefix>half_added_error_max_mm`, ...; `networks` says whose
// corrections set the figures).
void measure_storage_error(Bench& bench, const Model& model, const std::string& prefix, const std::string& networks) {
  const std::size_t n = std::min<std::size_t>(bench.frames, 100);
  double worst[2] = {0, 0}, mean[2] = {0, 0}, worst_sp[2] = {0, 0};
  const int32_t precisions[3] = {SOFTDECA_PRECISION_FLOAT, SOFTDECA_PRECISION_HALF, SOFTDECA_PRECISION_INT8};
  std::vector<std::vector<float>> ref_sd, ref_sp;
  const std::vector<float>& vertices = bench.vertices;
  for (int p = 0; p < 3; ++p) {
    Avatar a(model, bench.rig.neutral, bench.rig.deltas, 1, both(precisions[p]));
    check(softdeca_avatar_prepare(a.handle), "prepare");
    if (!bench.user.empty())
      check(softdeca_avatar_calibrate_landmarks(a.handle, bench.user.neutral.vertices.data(), bench.user.neutral.vertex_count()),
            "calibration");
    for (std::size_t f = 0; f < n; ++f) {
      check(softdeca_avatar_evaluate_weights(a.handle, bench.take.weights[f].data(), 52, &bench.output), "softdeca");
      std::vector<float> sd(vertices.begin(), vertices.begin() + 3 * model.info.skin_vertex_count);
      check(softdeca_avatar_evaluate_landmarks(a.handle, bench.input.points[f].data(), bench.input.point_count, &bench.output),
            "sparse");
      std::vector<float> sp(vertices.begin(), vertices.begin() + 3 * model.info.skin_vertex_count);
      if (p == 0) {
        ref_sd.push_back(std::move(sd));
        ref_sp.push_back(std::move(sp));
        continue;
      }
      for (std::size_t v = 0; v < model.info.skin_vertex_count; ++v) {
        double d2 = 0, e2 = 0;
        for (int c = 0; c < 3; ++c) {
          d2 += std::pow(sd[3 * v + c] - ref_sd[f][3 * v + c], 2);
          e2 += std::pow(sp[3 * v + c] - ref_sp[f][3 * v + c], 2);
        }
        worst[p - 1] = std::max(worst[p - 1], std::sqrt(d2) * 1e3);
        mean[p - 1] += std::sqrt(d2) * 1e3 / static_cast<double>(n * model.info.skin_vertex_count);
        worst_sp[p - 1] = std::max(worst_sp[p - 1], std::sqrt(e2) * 1e3);
      }
    }
  }
  const char* names[2] = {"half", "int8"};
  for (int p = 0; p < 2; ++p) {
    const std::string what = std::string(" storage of the hyper-tensors against float, over ") + std::to_string(n) +
                             " frames of the take, all skin vertices (" + networks + ")";
    const std::string key = "runtime." + prefix + names[p];
    bench.figures.raw(key + "_added_error_max_mm", figure(worst[p], "mm", std::string("SoftDECA: max |x - x_float|, ") + names[p] + what));
    bench.figures.raw(key + "_added_error_mean_mm", figure(mean[p], "mm", std::string("SoftDECA: mean |x - x_float|, ") + names[p] + what));
    bench.figures.raw(key + "_added_error_sparse_max_mm",
                      figure(worst_sp[p], "mm", std::string("SparseSoftDECA: max |x - x_float|, ") + names[p] + what));
    std::fprintf(stderr, "%s%s storage: SoftDECA max %.5f mm, mean %.6f mm; sparse max %.5f mm\n", prefix.c_str(), names[p], worst[p],
                 mean[p], worst_sp[p]);
  }
}
// A user's own avatar (a whole body, another topology): the fit, loading it, and its frames
// against the template path's on the same take, alternating frame by frame (1 thread).
void measure_own_avatar(Bench& bench, const std::string& path) {
  const AvatarFile file = read_avatar_file(path);
  const softdeca_avatar_mesh mesh = file.abi_mesh();
  softdeca_fit_options options{};
  options.struct_size = sizeof options;
  check(softdeca_fit_options_init(&options), "fit options");
  std::vector<double> fit_s;
  std::unique_ptr<Fit> fit;
  for (int i = 0; i < 3; ++i) {
    const auto t0 = Clock::now();
    fit = std::make_unique<Fit>(bench.model, mesh, options);
    fit_s.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  }
  const std::string saved = bench.out_dir + "/byo.fit";
  check(softdeca_avatar_fit_save(fit->handle, saved.c_str()), "save the fit");
  std::vector<double> load_ms;
  for (int i = 0; i < 5; ++i) {
    const auto t0 = Clock::now();
    const Fit loaded(bench.model, saved);
    load_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  std::remove(saved.c_str());
  Avatar own(bench.model, *fit, mesh, 1, kHalf);
  Avatar plain(bench.model, bench.rig.neutral, bench.rig.deltas, 1, kHalf);
  check(softdeca_avatar_prepare(own.handle), "prepare");
  check(softdeca_avatar_prepare(plain.handle), "prepare");
  const auto n = static_cast<uint32_t>(file.vertex_count());
  std::vector<float> vertices(3 * n), normals(3 * n);
  softdeca_output out{sizeof(softdeca_output), vertices.data(), n, normals.data(), n};
  std::vector<double> own_ms, plain_ms;
  for (std::size_t i = 0; i < bench.warmup + bench.frames; ++i) {
    const float* w = bench.take.weights[i % bench.frames].data();
    const Times a = median_ms(1, 0, [&](std::size_t) { check(softdeca_avatar_evaluate_weights(own.handle, w, 52, &out), "own"); });
    const Times b = median_ms(1, 0, [&](std::size_t) {
      check(softdeca_avatar_evaluate_weights(plain.handle, w, 52, &bench.output), "template");
    });
    if (i >= bench.warmup) own_ms.push_back(a.wall), plain_ms.push_back(b.wall);
  }
  const std::string how = std::string("; ") + path + " (" + std::to_string(n) + " vertices, " + std::to_string(file.parts.size()) +
                          " parts); 1 thread; " + bench.how;
  bench.figures.raw("runtime.fit_s", figure(median(fit_s), "s", "softdeca_avatar_fit_create, median of 3" + how, 10.0));
  bench.figures.raw("runtime.fit_load_ms", figure(median(load_ms), "ms", "softdeca_avatar_fit_load of the saved fit, median of 5" + how));
  bench.figures.raw("runtime.byo_frame_ms",
                    figure(median(own_ms), "ms", "evaluate_weights on the fitted avatar, with normals, wall-clock" + how));
  bench.figures.raw("runtime.byo_over_template",
                    figure(median(own_ms) / median(plain_ms), "x",
                           "byo_frame_ms over the template path's frame on the same take, frames alternating" + how, 1.15));
  bench.figures.raw("runtime.byo_memory_mb",
                    figure(static_cast<double>(own.stats().memory_bytes) / (1 << 20), "MiB", "the fitted avatar's memory_bytes" + how));
  std::fprintf(stderr, "own avatar: fit %.2f s, load %.1f ms, frame %.3f ms (template %.3f ms)\n", median(fit_s), median(load_ms),
               median(own_ms), median(plain_ms));
}

// Frames of `a` and of `b` alternating on the same take (1 thread): per-frame medians of each,
// measured under the same conditions (cache, clock, other processes) so their ratio holds.
std::pair<double, double> alternating_ms(const Bench& bench, const std::function<void(std::size_t)>& a,
                                         const std::function<void(std::size_t)>& b) {
  std::vector<double> a_ms, b_ms;
  for (std::size_t i = 0; i < bench.warmup + bench.frames; ++i) {
    const std::size_t f = i % bench.frames;
    const Times x = median_ms(1, 0, [&](std::size_t) { a(f); });
    const Times y = median_ms(1, 0, [&](std::size_t) { b(f); });
    if (i >= bench.warmup) a_ms.push_back(x.wall), b_ms.push_back(y.wall);
  }
  return {median(a_ms), median(b_ms)};
}

// The template path as hosts run it, through the C ABI's handle (whose avatar is the identity
// fit: runtime/fitted_avatar.h runs one frame path for every mesh), against the core avatar of
// the same head on the same bundle evaluated directly (bench_core_avatar.h), frames alternating
// (1 thread): what the handle and the identity fit's transfer add to the template's frame.
void measure_identity_fit(Bench& bench, const std::string& bundle_path) {
  const FaceRig& rig = bench.rig;
  CoreAvatar core(bundle_path, rig.neutral.vertices, rig.neutral.triangles, rig.deltas);
  Avatar handle(bench.model, rig.neutral, rig.deltas, 1, kHalf);
  check(softdeca_avatar_prepare(handle.handle), "prepare");
  const std::size_t capacity = bench.vertices.size() / 3;
  const auto w = [&](std::size_t f) { return bench.take.weights[f].data(); };
  const auto [through_handle, direct] = alternating_ms(
      bench, [&](std::size_t f) { check(softdeca_avatar_evaluate_weights(handle.handle, w(f), 52, &bench.output), "handle"); },
      [&](std::size_t f) { core.evaluate_weights(w(f), bench.vertices.data(), bench.normals.data(), capacity); });
  char times[96];
  std::snprintf(times, sizeof times, " (%.3f against %.3f ms)", through_handle, direct);
  bench.figures.raw("runtime.identity_fit_overhead",
                    figure(through_handle / direct, "x",
                           std::string("the template head's evaluate_weights through the C ABI's handle (the identity fit) "
                                       "over the core avatar of the same head evaluated directly") +
                               times + ", dynamics off, with normals, frames alternating, medians, wall-clock; 1 thread; " +
                               bench.how,
                           1.05));
  std::fprintf(stderr, "identity fit: handle %.3f ms, core %.3f ms (x%.3f)\n", through_handle, direct, through_handle / direct);
}

// Several avatars of one bundle on one core, as crowds and collaborations run them: each frame
// of the take evaluated on every avatar in turn (each its own memory, as separate hosts' avatars
// are), so the figure pays for the caches they share. The per-avatar frame and how many avatars
// one core keeps at 60 fps.
constexpr std::size_t kCrowd = 16;
constexpr double kFrame60HzMs = 1000.0 / 60.0;

void measure_crowd(Bench& bench, Model& shipped, const std::string& how) {
  std::vector<std::unique_ptr<Avatar>> crowd;
  for (std::size_t i = 0; i < kCrowd; ++i) {
    crowd.push_back(std::make_unique<Avatar>(shipped, bench.rig.neutral, bench.rig.deltas, 1));
    check(softdeca_avatar_prepare(crowd.back()->handle), "prepare");
  }
  const Times t = median_ms(bench.frames, bench.warmup, [&](std::size_t f) {
    for (const auto& a : crowd)
      check(softdeca_avatar_evaluate_weights(a->handle, bench.take.weights[f].data(), 52, &bench.output), "crowd");
  });
  // the same frames in one softdeca_avatar_evaluate_weights_batch call a frame (the per-frame
  // networks once for the crowd), the crowd's weights side by side
  std::vector<softdeca_avatar*> handles;
  for (const auto& a : crowd) handles.push_back(a->handle);
  const std::vector<softdeca_output> outputs(kCrowd, bench.output);
  std::vector<float> weights(kCrowd * 52);
  std::vector<int32_t> statuses(kCrowd);
  const Times b = median_ms(bench.frames, bench.warmup, [&](std::size_t f) {
    for (std::size_t i = 0; i < kCrowd; ++i) std::copy_n(bench.take.weights[f].data(), 52, weights.data() + 52 * i);
    check(softdeca_avatar_evaluate_weights_batch(handles.data(), kCrowd, weights.data(), 52, outputs.data(), statuses.data()),
          "crowd batch");
    for (const int32_t s : statuses) check(static_cast<softdeca_status>(s), "crowd batch avatar");
  });
  const double per_avatar = t.wall / static_cast<double>(kCrowd), per_batched = b.wall / static_cast<double>(kCrowd);
  const std::string crowd_how = "; " + std::to_string(kCrowd) + " avatars of the shipped bundle on the template head (the library's "
                                "default precisions), each frame "
                                "evaluated on every one in turn (evaluate_weights, with normals), median frame over the " +
                                std::to_string(kCrowd) + "; 1 thread" + how;
  const std::string batch_how = "; the same " + std::to_string(kCrowd) +
                                " avatars and frames, each frame one softdeca_avatar_evaluate_weights_batch call for all of "
                                "them (the per-frame networks run once), median frame over the " +
                                std::to_string(kCrowd) + "; 1 thread" + how;
  bench.figures.raw("runtime.crowd_softdeca_ms_per_avatar", figure(per_avatar, "ms", "wall-clock per avatar" + crowd_how));
  bench.figures.raw("runtime.avatars_per_core_60fps",
                    figure(std::floor(kFrame60HzMs / per_avatar), "avatars",
                           "avatars one core keeps at 60 fps: floor(16.67 ms / crowd_softdeca_ms_per_avatar)" + crowd_how, 12.0,
                           "higher"));
  bench.figures.raw("runtime.crowd_batch_softdeca_ms_per_avatar", figure(per_batched, "ms", "wall-clock per avatar" + batch_how));
  bench.figures.raw("runtime.avatars_per_core_60fps_batch",
                    figure(std::floor(kFrame60HzMs / per_batched), "avatars",
                           "avatars one core keeps at 60 fps in batch calls: floor(16.67 ms / "
                           "crowd_batch_softdeca_ms_per_avatar)" + batch_how,
                           12.0, "higher"));
  std::fprintf(stderr, "crowd of %zu: %.3f ms per avatar frame (%.0f per core at 60 fps); in batch calls %.3f ms (%.0f)\n",
               kCrowd, per_avatar, std::floor(kFrame60HzMs / per_avatar), per_batched, std::floor(kFrame60HzMs / per_batched));
}

// The least bytes of a kind of frame (softdeca_stats.frame_bytes) over the take's frames, median
// (only the blend's share changes from frame to frame: the shapes the weights move).
double median_frame_bytes(const Bench& bench, const Avatar& a, const std::function<void(std::size_t)>& frame) {
  std::vector<double> bytes;
  for (std::size_t f = 0; f < bench.frames; ++f) {
    frame(f);
    bytes.push_back(static_cast<double>(a.stats().frame_bytes));
  }
  return median(bytes);
}

// The frames' times against the memory-bandwidth limit: the machine's streaming read bandwidth
// on one thread, the least bytes each kind of frame moves, and the share of its measured time
// that moving them at that bandwidth takes ((bytes / bandwidth) / time: 1 is a frame bound by
// memory alone).
struct FrameKind {
  const char* name;   // the figures' prefix
  const char* timed;  // the figure of its time
  double ms;
  const Avatar* avatar;  // whose stats the frame sets
  std::string how;       // what was timed
  std::function<void(std::size_t)> frame;
};

// The machine's streaming read bandwidth, measured once a run (the first call records the figure).
double read_bandwidth(Bench& bench) {
  if (bench.copy_read_gb_s > 0) return bench.copy_read_gb_s;
  const double gb_s = bench.copy_read_gb_s = streaming_read_gb_s();
  const std::string bandwidth_how = "a sum of 64-bit words over " + std::to_string(kBandwidthBufferBytes >> 20) +
                                    " MiB written beforehand, best of " + std::to_string(kBandwidthPasses) +
                                    " passes, 1 thread, measured once in the run, right after the first frames set against "
                                    "it; " + bench.how;
  bench.figures.raw("runtime.copy_read_gb_s", figure(gb_s, "GB/s", "streaming read bandwidth: " + bandwidth_how, NAN, "higher"));
  std::fprintf(stderr, "streaming read bandwidth %.2f GB/s\n", gb_s);
  return gb_s;
}

void measure_bandwidth_share(Bench& bench, const std::vector<FrameKind>& kinds) {
  const double gb_s = read_bandwidth(bench);
  for (const FrameKind& k : kinds) {
    const double bytes = median_frame_bytes(bench, *k.avatar, k.frame);
    const double limit_ms = bytes / (gb_s * 1e9) * 1e3;
    const std::string name = k.name;
    bench.figures.raw("runtime." + name + "_bytes_per_frame",
                      figure(bytes, "bytes/frame", "softdeca_stats.frame_bytes (the least bytes the frame reads and writes "
                                                   "in memory, docs/runtime.md), median over the take's frames" + k.how));
    bench.figures.raw("runtime." + name + "_bandwidth_share",
                      figure(limit_ms / k.ms, "ratio", name + "_bytes_per_frame / copy_read_gb_s (" + std::to_string(limit_ms) +
                                                           " ms) over " + k.timed + k.how, NAN, "higher"));
    std::fprintf(stderr, "%s: %.0f bytes, %.3f ms at that rate of %.3f ms (%.2f)\n", k.name, bytes, limit_ms, k.ms,
                 limit_ms / k.ms);
  }
}

// The path users run: the shipped (trained) bundle at the library's default precisions, on the
// template and on a fitted avatar, each against its own linear blend with frames alternating,
// and SparseSoftDECA (1 thread).
void measure_shipped(Bench& bench, const std::string& bundle_path, const std::string& own_path) {
  Model shipped(bundle_path);
  const auto w = [&](std::size_t f) { return bench.take.weights[f].data(); };
  Avatar head(shipped, bench.rig.neutral, bench.rig.deltas, 1);
  check(softdeca_avatar_prepare(head.handle), "prepare");
  if (!bench.user.empty())
    check(softdeca_avatar_calibrate_landmarks(head.handle, bench.user.neutral.vertices.data(), bench.user.neutral.vertex_count()),
          "calibration");
  softdeca_output* out = &bench.output;
  const auto [softdeca, linear] = alternating_ms(
      bench, [&](std::size_t f) { check(softdeca_avatar_evaluate_weights(head.handle, w(f), 52, out), "softdeca"); },
      [&](std::size_t f) { check(softdeca_avatar_evaluate_linear(head.handle, w(f), 52, out), "linear"); });
  const Frames& input = bench.input;
  const auto [sparse, linear_again] = alternating_ms(
      bench,
      [&](std::size_t f) { check(softdeca_avatar_evaluate_landmarks(head.handle, input.points[f].data(), input.point_count, out), "sparse"); },
      [&](std::size_t f) { check(softdeca_avatar_evaluate_linear(head.handle, w(f), 52, out), "linear"); });
  const auto template_how = [&](const std::string& storage) {
    return "; the shipped bundle " + bundle_path + ", the template head, " + storage + ", dynamics off, with normals, frames "
           "alternating with the linear blend of the same avatar, wall-clock; 1 thread; " + bench.how;
  };
  const std::string how = template_how("the library's default precisions");
  bench.figures.raw("runtime.shipped_softdeca_ms", figure(softdeca, "ms", "evaluate_weights" + how));
  bench.figures.raw("runtime.shipped_linear_ms", figure(linear, "ms", "evaluate_linear" + how));
  bench.figures.raw("runtime.shipped_softdeca_over_linear",
                    figure(softdeca / linear, "x", "shipped_softdeca_ms / shipped_linear_ms" + how, 1.5));
  bench.figures.raw("runtime.sparse_shipped_ms", figure(sparse, "ms", "evaluate_landmarks" + how));
  bench.figures.raw("runtime.sparse_shipped_over_linear",
                    figure(sparse / linear_again, "x", "sparse_shipped_ms over the linear blend's frames between them" + how));
  std::fprintf(stderr, "shipped bundle, template: softdeca %.3f ms, linear %.3f ms (x%.2f); sparse %.3f ms\n", softdeca, linear,
               softdeca / linear, sparse);
  measure_bandwidth_share(
      bench,
      {{"softdeca", "shipped_softdeca_ms", softdeca, &head, how,
        [&](std::size_t f) { check(softdeca_avatar_evaluate_weights(head.handle, w(f), 52, out), "softdeca"); }},
       {"sparse", "sparse_shipped_ms", sparse, &head, how,
        [&](std::size_t f) {
          check(softdeca_avatar_evaluate_landmarks(head.handle, input.points[f].data(), input.point_count, out), "sparse");
        }},
       {"linear", "shipped_linear_ms", linear, &head, how,
        [&](std::size_t f) { check(softdeca_avatar_evaluate_linear(head.handle, w(f), 52, out), "linear"); }}});
  // The same head with SoftDECA's tables in half (twice int8's bytes), against its own linear
  // blend in the same way, and what each compact storage adds to the trained networks' output.
  Avatar head_half(shipped, bench.rig.neutral, bench.rig.deltas, 1, {SOFTDECA_PRECISION_HALF, SOFTDECA_PRECISION_DEFAULT});
  check(softdeca_avatar_prepare(head_half.handle), "prepare");
  const auto [softdeca_half, linear_half] = alternating_ms(
      bench, [&](std::size_t f) { check(softdeca_avatar_evaluate_weights(head_half.handle, w(f), 52, out), "softdeca"); },
      [&](std::size_t f) { check(softdeca_avatar_evaluate_linear(head_half.handle, w(f), 52, out), "linear"); });
  const std::string half_how = template_how("SoftDECA's tables (hyper-tensor, vertex and residual stages) in half");
  bench.figures.raw("runtime.shipped_softdeca_ms_half", figure(softdeca_half, "ms", "evaluate_weights" + half_how));
  bench.figures.raw("runtime.shipped_softdeca_over_linear_half",
                    figure(softdeca_half / linear_half, "x", "shipped_softdeca_ms_half over the linear blend's frames between them" +
                                                                 half_how, 1.5));
  std::fprintf(stderr, "shipped bundle, template, SoftDECA in half: softdeca %.3f ms, linear %.3f ms (x%.2f)\n", softdeca_half,
               linear_half, softdeca_half / linear_half);
  measure_storage_error(bench, shipped, "shipped_", "the shipped bundle's trained networks, the template head");
  measure_crowd(bench, shipped, "; " + bench.how);
  if (own_path.empty()) return;
  const AvatarFile file = read_avatar_file(own_path);
  const softdeca_avatar_mesh mesh = file.abi_mesh();
  softdeca_fit_options options{};
  options.struct_size = sizeof options;
  check(softdeca_fit_options_init(&options), "fit options");
  const Fit fit(shipped, mesh, options);
  Avatar own(shipped, fit, mesh, 1);
  check(softdeca_avatar_prepare(own.handle), "prepare");
  const auto n = static_cast<uint32_t>(file.vertex_count());
  std::vector<float> vertices(3 * n), normals(3 * n);
  softdeca_output own_out{sizeof(softdeca_output), vertices.data(), n, normals.data(), n};
  const auto [own_softdeca, own_linear] = alternating_ms(
      bench, [&](std::size_t f) { check(softdeca_avatar_evaluate_weights(own.handle, w(f), 52, &own_out), "softdeca"); },
      [&](std::size_t f) { check(softdeca_avatar_evaluate_linear(own.handle, w(f), 52, &own_out), "linear"); });
  const std::string own_how = "; the shipped bundle " + bundle_path + " fitted to " + own_path + " (" + std::to_string(n) +
                              " vertices), the library's default precisions, dynamics off, with normals, frames alternating with "
                              "the avatar's own linear blend, "
                              "wall-clock; 1 thread; " + bench.how;
  bench.figures.raw("runtime.shipped_softdeca_fitted_ms", figure(own_softdeca, "ms", "evaluate_weights" + own_how));
  bench.figures.raw("runtime.shipped_softdeca_over_linear_fitted",
                    figure(own_softdeca / own_linear, "x", "shipped_softdeca_fitted_ms over the avatar's evaluate_linear" + own_how, 1.6));
  std::fprintf(stderr, "shipped bundle, fitted avatar: softdeca %.3f ms, linear %.3f ms (x%.2f)\n", own_softdeca, own_linear,
               own_softdeca / own_linear);
}
// The deformation-transfer path: the benchmark's random bundle, whose every stage is nonzero,
// in the library's default precisions, against the same avatar's linear blend with frames
// alternating (as the shipped bundle's frames), and against the memory bandwidth.
void measure_dt_path(Bench& bench) {
  const auto w = [&](std::size_t f) { return bench.take.weights[f].data(); };
  softdeca_output* out = &bench.output;
  Avatar dt(bench.model, bench.rig.neutral, bench.rig.deltas, 1);
  check(softdeca_avatar_prepare(dt.handle), "prepare");
  const auto softdeca = [&](std::size_t f) { check(softdeca_avatar_evaluate_weights(dt.handle, w(f), 52, out), "softdeca"); };
  const auto [dt_softdeca, dt_linear] = alternating_ms(
      bench, softdeca, [&](std::size_t f) { check(softdeca_avatar_evaluate_linear(dt.handle, w(f), 52, out), "linear"); });
  const std::string dt_how = "; the benchmark's random bundle (the deformation-transfer path), the template head, the "
                             "library's default precisions, dynamics off, with normals, frames alternating with the linear "
                             "blend of the same avatar, wall-clock; 1 thread; " + bench.how;
  bench.figures.raw("runtime.dt_softdeca_ms", figure(dt_softdeca, "ms", "evaluate_weights" + dt_how));
  bench.figures.raw("runtime.dt_softdeca_over_linear",
                    figure(dt_softdeca / dt_linear, "x", "dt_softdeca_ms over the linear blend's frames between them" + dt_how, 3.0));
  std::fprintf(stderr, "random bundle (deformation transfer), default precisions: softdeca %.3f ms, linear %.3f ms (x%.2f)\n",
               dt_softdeca, dt_linear, dt_softdeca / dt_linear);
  measure_bandwidth_share(bench, {{"dt", "dt_softdeca_ms", dt_softdeca, &dt, dt_how, softdeca}});
}

}  // namespace

int run_bench_runtime(const Args& args) {
  Options o("bench-runtime", "Measure the runtime per frame on the frames of a take (medians), single- and two-threaded,\n"
                             "and write the benchmark JSON (docs/ARCHITECTURE.md, Conventions).");
  declare_model_inputs(o);
  o.option("--take", "FILE", "Live Link Face CSV or recording whose frames drive the measurement")
      .option("--frames", "N", "frames measured per figure", "600")
      .option("--warmup", "N", "frames run before measuring", "30")
      .option("--prepares", "N", "prepares measured", "5")
      .option("--out", "FILE", "benchmark JSON", "build/bench/runtime.json")
      .option("--own-avatar", "MESH", "a user's avatar (glTF, FBX or avatar folder) to fit and run against the template path")
      .option("--shipped-bundle", "DIR", "a trained bundle to time as users run it (the template, and --own-avatar fitted)")
      .option("--how", "TEXT", "the command line to record in the figures", "softdeca bench-runtime");
  if (!o.parse(args)) return 0;
  require_model_inputs(o);
  if (!o.given("--take")) throw UsageError("--take is required");
  const Take take = read_take(o.text("--take"), static_cast<std::size_t>(o.integer("--frames")));
  const std::size_t frames = take.weights.size();
  const FaceRig rig = read_rig(o.text("--avatar"));
  const FaceRig user = read_rig(o.text("--avatar"), "user_face", true);
  Model model(o.text("--bundle"));
  const uint32_t vh = model.info.head_vertex_count;
  Bench bench{take, rig, user, model, frames, static_cast<std::size_t>(o.integer("--warmup")), o.integer("--prepares"),
              o.text("--how") + " on " + cpu_name() + " (" + std::to_string(std::thread::hardware_concurrency()) + " cores); " +
                  std::to_string(frames) + " frames of " + take.path + ", median; " +
                  std::to_string(model.info.skin_triangle_count) + " skin triangles, " + std::to_string(vh) + " head vertices" +
                  (model.info.untrained ? ", untrained (random) networks of full size" : ""),
              sparse_inputs(take, frames, rig, user, model), std::vector<float>(vh * 3), std::vector<float>(vh * 3), {}, {}, {}};
  bench.output = {sizeof(softdeca_output), bench.vertices.data(), vh, bench.normals.data(), vh};
  {
    const std::string out = o.text("--out");
    const std::size_t slash = out.rfind('/');
    bench.out_dir = slash == std::string::npos ? "." : out.substr(0, slash);
    make_directories(bench.out_dir);
  }

  for (const unsigned threads : {1u, 2u}) measure_with_threads(bench, threads);
  measure_identity_fit(bench, o.text("--bundle"));
  for (const int32_t precision : {SOFTDECA_PRECISION_INT8, SOFTDECA_PRECISION_FLOAT}) measure_storage(bench, precision);
  measure_storage_error(bench, bench.model, "", "untrained networks: the size of their corrections sets this");
  measure_rest_physics(bench);
  if (o.given("--own-avatar")) measure_own_avatar(bench, o.text("--own-avatar"));
  if (o.given("--shipped-bundle")) measure_shipped(bench, o.text("--shipped-bundle"), o.given("--own-avatar") ? o.text("--own-avatar") : "");
  measure_dt_path(bench);

  const std::string path = o.text("--out");
  const std::size_t slash = path.rfind('/');
  if (slash != std::string::npos) make_directories(path.substr(0, slash));
  write_text_file(path, bench.figures.str(true) + "\n");
  std::printf("wrote %s\n", path.c_str());
  return 0;
}
}  // namespace softdeca::cli
