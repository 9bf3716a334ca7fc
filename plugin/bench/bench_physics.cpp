// Micro-benchmark of the physics model phi† on synthetic layered heads at several wrap
// resolutions: time per static frame to convergence, per dynamic frame, iterations, the
// share of local and global steps, factorisation time, batched frames per second.
// Writes a JSON object of figures {"value", "unit", "target", "better", "how"} (docs/ARCHITECTURE.md, Conventions).
//
//   bench_physics [--out build/bench/physics.json] [--levels 3,4,5] [--default 4]
//                 [--frames 8] [--repeats 3] [--threads 0]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "sim/simulator.h"
#include "sim/synthetic.h"

using namespace softdeca::sim;

namespace {
struct Options {
  std::string out = "build/bench/physics.json";
  std::vector<int> levels = {3, 4, 5};
  int default_level = 4;
  int frames = 8;
  int repeats = 3;
  int threads = 0;
};

// Process CPU time (all threads): under a shared, loaded machine wall time measures the load
// as much as the work; both are reported.
double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? NAN : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Frames of a smooth expression-like animation: a bump on the face side that grows, moves
// sideways and pulls the jaw side down, up to 8 mm.
std::vector<FrameInput> animation(const SimulationMesh& mesh, int frames) {
  const Positions rest = embed(mesh.skin, mesh.rest);
  std::vector<FrameInput> out(static_cast<std::size_t>(frames));
  for (int f = 0; f < frames; ++f) {
    const double phase = frames > 1 ? static_cast<double>(f) / (frames - 1) : 1.0;
    const Eigen::Vector3d centre = Eigen::Vector3d(0.4 * std::sin(3 * phase), -0.2, 1).normalized();
    Positions t = rest;
    for (Eigen::Index i = 0; i < t.rows(); ++i) {
      const Eigen::Vector3d n = rest.row(i).transpose().normalized();
      const double w = std::max(0.0, n.dot(centre));
      t.row(i) += (0.008 * (0.3 + 0.7 * phase) * w * w * w) * n.transpose();
      if (n.y() < -0.3) t(i, 1) -= 0.004 * phase * (-n.y() - 0.3);
    }
    out[static_cast<std::size_t>(f)].skin_targets = t;
  }
  return out;
}

struct Figure {
  double value;
  std::string unit;
  double target;  // NaN: none
  std::string better;
  std::string how;
};

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o + "\"";
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "missing value after " << a << "\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--out") o.out = next();
    else if (a == "--levels") {
      o.levels.clear();
      std::stringstream ss(next());
      for (std::string item; std::getline(ss, item, ',');) o.levels.push_back(std::stoi(item));
    } else if (a == "--default") o.default_level = std::stoi(next());
    else if (a == "--frames") o.frames = std::stoi(next());
    else if (a == "--repeats") o.repeats = std::stoi(next());
    else if (a == "--threads") o.threads = std::stoi(next());
    else {
      std::cerr << "usage: bench_physics [--out FILE] [--levels 3,4,5] [--default 4] [--frames 8] [--repeats 3] "
                   "[--threads 0]\n";
      std::exit(a == "--help" || a == "-h" ? 0 : 2);
    }
  }
  return o;
}
// The benchmark JSON ({name: {value, unit, target, better, how}}); false when it cannot be written.
bool write_figures(const std::string& path, const std::map<std::string, Figure>& figures) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream out(path);
  if (!out) {
    std::cerr << "cannot write " << path << "\n";
    return false;
  }
  out << "{\n";
  std::size_t i = 0;
  for (const auto& [name, f] : figures) {
    char value[64];
    std::snprintf(value, sizeof value, "%.6g", f.value);
    out << "  " << json_string(name) << ": {\"value\": " << value << ", \"unit\": " << json_string(f.unit)
        << ", \"target\": " << (std::isnan(f.target) ? std::string("null") : std::to_string(f.target))
        << ", \"better\": " << json_string(f.better) << ", \"how\": " << json_string(f.how) << "}"
        << (++i < figures.size() ? "," : "") << "\n";
  }
  out << "}\n";
  return true;
}
}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  std::map<std::string, Figure> figures;
  std::string command = "bench_physics";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const int threads = o.threads > 0 ? o.threads : static_cast<int>(hw);

  for (int level : o.levels) {
    SyntheticHeadOptions ho;
    ho.subdivisions = level;
    ho.skin_subdivisions = level + 1;
    const SimulationMesh mesh = synthetic_layered_head(ho);
    const long tets = static_cast<long>(mesh.soft_tets.rows() + mesh.muscle_tets.rows() + mesh.connecting_tets.rows());
    char size[200];
    std::snprintf(size, sizeof size, "%ld tets (%ld soft, %ld muscle, %ld connecting), %ld vertices, S %ld points",
                  tets, static_cast<long>(mesh.soft_tets.rows()), static_cast<long>(mesh.muscle_tets.rows()),
                  static_cast<long>(mesh.connecting_tets.rows()), static_cast<long>(mesh.vertex_count()),
                  static_cast<long>(mesh.skin_count()));
    const std::string how = command + " (synthetic layered head, wraps level " + std::to_string(level) + ": " + size +
                            "; " + std::to_string(threads) + " threads, default parameters and settings)";
    const std::vector<FrameInput> frames = animation(mesh, o.frames);

    SolverSettings settings;
    settings.threads = threads;
    settings.record_energy = false;
    Simulator sim(mesh, settings);
    // Static frames, each from rest (cold): time to convergence.
    std::vector<double> t_static, cpu_static, it_static, local_share, global_share;
    double factor = 0;
    int converged = 0, solved = 0;
    for (int r = 0; r < o.repeats; ++r)
      for (const FrameInput& f : frames) {
        const double c0 = cpu_seconds();
        const FrameResult res = sim.solve_static(f);
        cpu_static.push_back(cpu_seconds() - c0);
        factor += res.stats.factor_seconds;
        const double solve = res.stats.total_seconds;
        t_static.push_back(solve);
        it_static.push_back(res.stats.iterations);
        local_share.push_back(res.stats.local_seconds / solve);
        global_share.push_back(res.stats.global_seconds / solve);
        converged += res.stats.converged;
        ++solved;
      }
    // Dynamic frames: a sequence (gamma 0.5, beta 0.5), each frame from the previous one.
    sim.parameters().set("dyn_gamma", 0.5);
    sim.parameters().set("dyn_beta", 0.5);
    std::vector<double> t_dynamic, cpu_dynamic, it_dynamic;
    for (int r = 0; r < o.repeats; ++r) {
      sim.reset_dynamics();
      sim.step_dynamic(frames.front());  // the static start, not a dynamic frame
      for (std::size_t f = 1; f < frames.size(); ++f) {
        const double c0 = cpu_seconds();
        const FrameResult res = sim.step_dynamic(frames[f]);
        cpu_dynamic.push_back(cpu_seconds() - c0);
        t_dynamic.push_back(res.stats.total_seconds);
        it_dynamic.push_back(res.stats.iterations);
      }
    }
    // Batched static frames over one factorisation: contiguous chunks per thread.
    sim.parameters().set("dyn_gamma", 1.0);
    sim.parameters().set("dyn_beta", 0.0);
    sim.solve_static(frames.front());  // factorise outside the timing
    std::vector<double> fps;
    for (int r = 0; r < o.repeats; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      sim.solve_static_batch(frames);
      fps.push_back(static_cast<double>(frames.size()) /
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }

    const std::string k = ".level" + std::to_string(level);
    const bool headline = level == o.default_level;
    auto put = [&](const std::string& name, Figure f) {
      figures["physics." + name + k] = f;
      if (headline) figures["physics." + name] = f;
    };
    put("static_frame_s", {median(t_static), "s", 1.0, "lower", how + "; median over " + std::to_string(solved) +
                                                                    " frames from rest, " + std::to_string(converged) +
                                                                    " converged"});
    put("dynamic_frame_s", {median(t_dynamic), "s", NAN, "lower", how + "; median over dynamic frames (gamma 0.5, beta 0.5)"});
    put("batched_frames_per_s", {median(fps), "frames/s", NAN, "higher", how + "; solve_static_batch of " +
                                                                             std::to_string(frames.size()) + " frames"});
    put("static_frame_cpu_s", {median(cpu_static), "CPU s (all threads)", NAN, "lower", how});
    put("dynamic_frame_cpu_s", {median(cpu_dynamic), "CPU s (all threads)", NAN, "lower", how});
    put("static_iterations", {median(it_static), "iterations", NAN, "lower", how});
    put("dynamic_iterations", {median(it_dynamic), "iterations", NAN, "lower", how});
    put("local_step_share", {median(local_share), "fraction of frame time", NAN, "lower", how});
    put("global_step_share", {median(global_share), "fraction of frame time", NAN, "lower", how});
    put("factorisation_s", {factor / std::max(1, sim.factorizations()), "s", NAN, "lower", how});
    put("tets", {static_cast<double>(tets), "tets", NAN, "higher", how});
    std::printf("level %d: %s\n  static %.3f s (%.3f CPU s, %.0f it, local %.0f%%, global %.0f%%, %d/%d converged), "
                "dynamic %.3f s (%.3f CPU s, %.0f it), batched %.2f frames/s, factorisation %.3f s\n",
                level, size, median(t_static), median(cpu_static), median(it_static), 100 * median(local_share),
                100 * median(global_share), converged, solved, median(t_dynamic), median(cpu_dynamic),
                median(it_dynamic), median(fps), factor / std::max(1, sim.factorizations()));
    std::fflush(stdout);
  }

  if (!write_figures(o.out, figures)) return 1;
  std::printf("wrote %s\n", o.out.c_str());
  return 0;
}
