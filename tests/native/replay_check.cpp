// A replay through the shared library's C ABI alone, compared with a `softdeca replay` point cache
// made by another build: the Windows DLL run under wine against the Linux replay of the same
// bundle, avatar and frames (tests/platforms/windows_replay_check.sh). Uses nothing but
// softdeca.h, so it builds wherever the library does.
//
// usage: replay_check BUNDLE AVATAR_DIR TAKE.sdrec FIRST_FRAME EXPECTED.pc2 TOLERANCE_METRES [PRECISION [MODEL [MODE]]]
//   AVATAR_DIR: neutral.obj and blendshapes/<ARKit name>.obj (as `softdeca replay --avatar` reads)
//   EXPECTED.pc2: `softdeca replay TAKE.sdrec --models MODEL --start FIRST_FRAME ...`
//   PRECISION: default (as softdeca replay), half, float or int8: both models' tables, the
//     replay's --precision and --sparse-precision
//   MODEL: softdeca (default) or sparse (driven by the landmarks of the avatar's linear blend)
//   MODE: static (default) or dynamic: the replay without or with --dynamics
// Also run on one machine under another kernel family (tests/cpu/run-as.sh, make test-kernels)
// and on the arm64 build under qemu against the x86-64 CLI (make test-arm64).
// Prints the largest vertex difference; exit status 0 when within the tolerance.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "softdeca/softdeca.h"

namespace {

void check(softdeca_status status, const std::string& what) {
  if (status != SOFTDECA_OK)
    throw std::runtime_error(what + ": " + softdeca_status_name(status) + ": " + softdeca_last_error());
}

struct Obj {
  std::vector<float> vertices;   // xyz
  std::vector<int32_t> triangles;  // faces fanned into triangles
};

// "v x y z" and "f a[/t/n] b c ..." lines; everything else is ignored.
Obj read_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  Obj obj;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      float x = 0, y = 0, z = 0;
      if (!(s >> x >> y >> z)) throw std::runtime_error(path + ": bad vertex line '" + line + "'");
      obj.vertices.insert(obj.vertices.end(), {x, y, z});
    } else if (tag == "f") {
      std::vector<int32_t> corners;
      std::string corner;
      while (s >> corner) corners.push_back(std::atoi(corner.c_str()) - 1);
      for (std::size_t k = 1; k + 1 < corners.size(); ++k)
        obj.triangles.insert(obj.triangles.end(), {corners[0], corners[k], corners[k + 1]});
    }
  }
  return obj;
}

struct Pc2 {
  uint32_t points = 0, frames = 0;
  std::vector<float> xyz;  // frames * points * 3
};

Pc2 read_pc2(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char signature[12] = {};
  int32_t version = 0, points = 0, frames = 0;
  float start = 0, rate = 0;
  in.read(signature, 12);
  in.read(reinterpret_cast<char*>(&version), 4).read(reinterpret_cast<char*>(&points), 4);
  in.read(reinterpret_cast<char*>(&start), 4).read(reinterpret_cast<char*>(&rate), 4);
  in.read(reinterpret_cast<char*>(&frames), 4);
  if (!in || std::strcmp(signature, "POINTCACHE2") != 0 || points <= 0 || frames <= 0)
    throw std::runtime_error(path + " is not a PC2 point cache");
  Pc2 pc2{static_cast<uint32_t>(points), static_cast<uint32_t>(frames), {}};
  pc2.xyz.resize(std::size_t{pc2.points} * pc2.frames * 3);
  if (!in.read(reinterpret_cast<char*>(pc2.xyz.data()), static_cast<std::streamsize>(pc2.xyz.size() * sizeof(float))))
    throw std::runtime_error(path + ": fewer frames than its header says");
  return pc2;
}

struct Options {
  std::string bundle, avatar_dir, take, expected_path, precision_name = "default", model_name = "softdeca";
  uint32_t first = 0;
  double tolerance = 0;
  int32_t precision = SOFTDECA_PRECISION_DEFAULT;
  bool sparse = false, dynamic = false;
};

// The arguments, or false (with the reason printed) when they are not a valid call.
bool parse(int argc, char** argv, Options& o) {
  if (argc < 7 || argc > 10) {
    std::fprintf(stderr, "usage: replay_check BUNDLE AVATAR_DIR TAKE.sdrec FIRST_FRAME EXPECTED.pc2 TOLERANCE_METRES "
                         "[default|half|float|int8 [softdeca|sparse [static|dynamic]]]\n");
    return false;
  }
  o.bundle = argv[1];
  o.avatar_dir = argv[2];
  o.take = argv[3];
  o.first = static_cast<uint32_t>(std::strtoul(argv[4], nullptr, 10));
  o.expected_path = argv[5];
  o.tolerance = std::strtod(argv[6], nullptr);
  if (argc > 7) o.precision_name = argv[7];
  if (argc > 8) o.model_name = argv[8];
  const std::string mode = argc > 9 ? argv[9] : "static";
  o.precision = o.precision_name == "float" ? SOFTDECA_PRECISION_FLOAT
                : o.precision_name == "int8" ? SOFTDECA_PRECISION_INT8
                : o.precision_name == "half" ? SOFTDECA_PRECISION_HALF
                : o.precision_name == "default" ? SOFTDECA_PRECISION_DEFAULT
                                             : -1;
  o.sparse = o.model_name == "sparse";
  o.dynamic = mode == "dynamic";
  if (o.precision < 0 || (!o.sparse && o.model_name != "softdeca") || (!o.dynamic && mode != "static")) {
    std::fprintf(stderr, "replay_check: precision default, half, float or int8; model softdeca or sparse; static or dynamic\n");
    return false;
  }
  return true;
}

// A neutral and its 52 ARKit blendshape deltas (as `softdeca replay` reads an avatar or user rig).
struct Rig {
  Obj neutral;
  std::vector<float> deltas;  // [52][3 n]
  bool empty() const { return neutral.vertices.empty(); }
  // out = neutral + sum_s w_s delta_s, in the CLI's order (FaceRig::blend).
  void blend(const float* w, float* out) const {
    const std::size_t n = neutral.vertices.size();
    std::copy(neutral.vertices.begin(), neutral.vertices.end(), out);
    for (std::size_t s = 0; s < SOFTDECA_BLENDSHAPE_COUNT; ++s) {
      if (w[s] == 0.0f) continue;
      const float* d = deltas.data() + s * n;
      for (std::size_t i = 0; i < n; ++i) out[i] += w[s] * d[i];
    }
  }
};

Rig read_rig(const std::string& dir, bool optional) {
  Rig rig;
  if (optional && !std::ifstream(dir + "/neutral.obj")) return rig;
  rig.neutral = read_obj(dir + "/neutral.obj");
  const std::size_t n = rig.neutral.vertices.size();
  rig.deltas.assign(SOFTDECA_BLENDSHAPE_COUNT * n, 0.0f);
  for (uint32_t b = 0; b < SOFTDECA_BLENDSHAPE_COUNT; ++b) {
    const std::string path = dir + "/blendshapes/" + softdeca_blendshape_get_name(b) + ".obj";
    if (!std::ifstream(path)) continue;  // a shape the avatar lacks: no motion (as softdeca replay)
    const Obj shape = read_obj(path);
    if (shape.vertices.size() != n) throw std::runtime_error(path + ": vertex count differs from the neutral");
    for (std::size_t i = 0; i < n; ++i) rig.deltas[b * n + i] = shape.vertices[i] - rig.neutral.vertices[i];
  }
  return rig;
}

// The avatar's rig as the C ABI's avatar, both models' tables at the given precision, prepared.
softdeca_avatar* make_avatar(softdeca_model* model, const Rig& rig, int32_t precision) {
  softdeca_avatar_mesh mesh{};
  mesh.struct_size = sizeof mesh;
  mesh.neutral = rig.neutral.vertices.data();
  mesh.vertex_count = static_cast<uint32_t>(rig.neutral.vertices.size() / 3);
  mesh.triangles = rig.neutral.triangles.data();
  mesh.triangle_count = static_cast<uint32_t>(rig.neutral.triangles.size() / 3);
  mesh.blendshapes = rig.deltas.data();
  mesh.blendshape_count = SOFTDECA_BLENDSHAPE_COUNT;
  softdeca_avatar_desc desc{};
  desc.struct_size = sizeof desc;
  desc.mesh = &mesh;
  desc.precision = precision;
  desc.sparse_precision = precision;
  softdeca_avatar* avatar = nullptr;
  check(softdeca_avatar_create(model, &desc, &avatar), "creating the avatar");
  check(softdeca_avatar_prepare(avatar), "prepare");
  return avatar;
}

// What SparseSoftDECA reads per frame, as `softdeca replay --models sparse` drives a template
// avatar: the user rig of AVATAR_DIR/user_face blended with the take (calibrated with its
// neutral), or without one the bundle's landmarks on the avatar's own linear blend.
struct Tracking {
  softdeca_model* model;
  softdeca_avatar* avatar;
  const softdeca_model_info& info;
  Rig user;
  std::vector<float> linear, points;

  Tracking(softdeca_model* m, softdeca_avatar* a, const softdeca_model_info& i, const std::string& avatar_dir)
      : model(m), avatar(a), info(i), user(read_rig(avatar_dir + "/user_face", true)) {
    linear.resize(3 * std::size_t{info.head_vertex_count});
    points.resize(user.empty() ? 3 * std::size_t{info.landmark_count} : user.neutral.vertices.size());
    if (!user.empty())
      check(softdeca_avatar_calibrate_landmarks(avatar, user.neutral.vertices.data(),
                                                static_cast<uint32_t>(user.neutral.vertices.size() / 3)),
            "calibration");
  }

  void evaluate(const float* weights, softdeca_output& output) {
    if (!user.empty()) {
      user.blend(weights, points.data());
    } else {
      softdeca_output linear_out{sizeof(softdeca_output), linear.data(), info.head_vertex_count, nullptr, 0};
      check(softdeca_avatar_evaluate_linear(avatar, weights, SOFTDECA_BLENDSHAPE_COUNT, &linear_out), "linear blend");
      check(softdeca_model_evaluate_landmarks(model, linear.data(), info.head_vertex_count, points.data(), info.landmark_count),
            "landmarks");
    }
    check(softdeca_avatar_evaluate_landmarks(avatar, points.data(), static_cast<uint32_t>(points.size() / 3), &output),
          "frame");
  }
};

int run(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) return 2;
  softdeca_model* model = nullptr;
  softdeca_model_options options{};
  options.struct_size = sizeof options;
  check(softdeca_model_load(o.bundle.c_str(), &options, &model), "loading " + o.bundle);
  softdeca_model_info info{};
  info.struct_size = sizeof info;
  check(softdeca_model_get_info(model, &info), "model info");
  if (o.sparse ? !info.has_sparse : !info.has_softdeca) throw std::runtime_error(o.bundle + " has no " + o.model_name + " model");

  const Rig rig = read_rig(o.avatar_dir, false);
  const Obj& neutral = rig.neutral;
  softdeca_avatar* avatar = make_avatar(model, rig, o.precision);
  check(softdeca_avatar_set_dynamics(avatar, o.dynamic ? SOFTDECA_TRUE : SOFTDECA_FALSE), "dynamics");
  softdeca_player* player = nullptr;
  check(softdeca_player_load(o.take.c_str(), &player), "opening " + o.take);
  const Pc2 expected = read_pc2(o.expected_path);
  if (expected.points != info.head_vertex_count)
    throw std::runtime_error(o.expected_path + " has " + std::to_string(expected.points) + " points, the bundle's head " +
                             std::to_string(info.head_vertex_count));

  std::vector<float> vertices(std::size_t{info.head_vertex_count} * 3);
  Tracking tracking(model, avatar, info, o.avatar_dir);
  softdeca_output output{sizeof(softdeca_output), vertices.data(), info.head_vertex_count, nullptr, 0};
  softdeca_frame frame{};
  double worst = 0, motion = 0;
  for (uint32_t f = 0; f < expected.frames; ++f) {
    frame.struct_size = sizeof frame;
    check(softdeca_player_get_frame(player, o.first + f, &frame), "take frame " + std::to_string(o.first + f));
    if (o.sparse) tracking.evaluate(frame.weights, output);
    else check(softdeca_avatar_evaluate_weights(avatar, frame.weights, SOFTDECA_BLENDSHAPE_COUNT, &output), "frame");
    const float* want = expected.xyz.data() + std::size_t{f} * expected.points * 3;
    for (std::size_t v = 0; v < expected.points; ++v) {
      double d2 = 0, m2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double d = double(vertices[3 * v + k]) - want[3 * v + k];
        const double m = double(vertices[3 * v + k]) - neutral.vertices[3 * v + k];
        d2 += d * d;
        m2 += m * m;
      }
      worst = std::max(worst, std::sqrt(d2));
      motion = std::max(motion, std::sqrt(m2));
    }
  }
  softdeca_player_destroy(player);
  softdeca_avatar_destroy(avatar);
  softdeca_model_destroy(model);

  // The largest motion off the neutral shows the frames animate (a comparison of two rest poses
  // would pass trivially).
  const bool ok = worst <= o.tolerance && motion > 10 * o.tolerance;
  std::printf("replay_check (softdeca %s, %s, %s, %s): %u frames x %u vertices, largest difference %.3g m (tolerance "
              "%.3g m), largest motion %.3g m: %s\n",
              softdeca_version(), o.model_name.c_str(), o.precision_name.c_str(), o.dynamic ? "dynamic" : "static",
              expected.frames, expected.points, worst, o.tolerance, motion, ok ? "OK" : "FAILED");
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "replay_check: %s\n", e.what());
    return 1;
  }
}
