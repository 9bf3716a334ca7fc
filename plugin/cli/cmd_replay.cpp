// softdeca replay: a take (Live Link Face CSV or recording) through plain linear blendshapes, SoftDECA (from the weights) and
// SparseSoftDECA (from landmarks) onto one avatar: a head in the template's topology, or a user's
// own mesh through its fit (replay_avatar.h). Writes per model a PC2 point cache over the
// avatar's neutral OBJ, both in the avatar's own meshes' coordinates (Blender: import
// neutral.obj, add a Mesh Cache modifier; Unity: the OBJ sequence of --obj-every) and replay.json
// with the timing summary. Native end to end: a template avatar (e.g. an ICT identity: python -m
// softdeca_train avatar) and the contact sheet of the output (python -m softdeca_train
// replay-preview) come from the training package, before and after.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "avatar_view.h"
#include "command.h"
#include "fit_options_arg.h"
#include "json.h"
#include "mesh_io.h"
#include "options.h"
#include "read_limits_arg.h"
#include "replay_avatar.h"
#include "runtime_session.h"
#include "take.h"

namespace softdeca::cli {

namespace {
using Clock = std::chrono::steady_clock;

struct Change {
  std::string name;
  float value = 0;
  std::string bound;  // "min", "max" or "default": the bundle's value, resolved when applied
  bool region = false;
  double centre[3] = {0, 0, 0}, radius = 0;
};

// "name=value" or "name=value@x,y,z,r" (faces whose neutral centroid lies within r metres);
// value may be min, max or default (the bundle's, which depend on the data it was trained on).
Change parse_change(const std::string& spec) {
  Change c;
  const std::size_t eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) throw UsageError("expected name=value[@x,y,z,r], got '" + spec + "'");
  c.name = spec.substr(0, eq);
  const std::size_t at = spec.find('@', eq);
  const std::string value = spec.substr(eq + 1, at == std::string::npos ? std::string::npos : at - eq - 1);
  char* end = nullptr;
  if (value == "min" || value == "max" || value == "default") {
    c.bound = value;
  } else {
    c.value = std::strtof(value.c_str(), &end);
    if (end == value.c_str() || *end) throw UsageError("bad value in '" + spec + "'");
  }
  if (at != std::string::npos) {
    std::stringstream region(spec.substr(at + 1));
    std::string item;
    double v[4];
    for (int i = 0; i < 4; ++i) {
      if (!std::getline(region, item, ',')) throw UsageError("region needs x,y,z,r in '" + spec + "'");
      v[i] = std::strtod(item.c_str(), &end);
      if (end == item.c_str()) throw UsageError("bad region number in '" + spec + "'");
    }
    c.region = true;
    for (int i = 0; i < 3; ++i) c.centre[i] = v[i];
    c.radius = v[3];
  }
  return c;
}

std::vector<Change> parse_changes(const std::string& list) {
  std::vector<Change> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ';'))
    if (!item.empty()) out.push_back(parse_change(item));
  return out;
}

// Applies changes; returns the number of faces a regional change covered (the skin's faces of a
// template avatar, the user's own faces of a fitted one).
std::size_t apply(const Model& model, ReplayAvatar& target, const std::vector<Change>& changes) {
  std::size_t covered = 0;
  const std::vector<std::int32_t>& tri = target.map_triangles;
  const std::vector<float>& neutral = target.map_vertices;
  softdeca_avatar* avatar = target.avatar->handle;
  for (Change c : changes) {
    const int index = model.parameter(c.name);
    if (!c.bound.empty()) {
      softdeca_parameter_info info{};
      info.struct_size = sizeof info;
      check(softdeca_model_get_parameter_info(model.handle, static_cast<uint32_t>(index), &info), "parameter " + c.name);
      c.value = static_cast<float>(c.bound == "min" ? info.minimum : c.bound == "max" ? info.maximum : info.default_value);
      std::fprintf(stderr, "%s=%s: %g\n", c.name.c_str(), c.bound.c_str(), static_cast<double>(c.value));
    }
    if (!c.region) {
      check(softdeca_avatar_set_parameter(avatar, static_cast<uint32_t>(index), c.value), "setting " + c.name);
      continue;
    }
    double current = 0;
    check(softdeca_avatar_get_parameter(avatar, static_cast<uint32_t>(index), &current, nullptr), "parameter");
    std::vector<float> map(tri.size() / 3, static_cast<float>(current));
    for (std::size_t f = 0; f < map.size(); ++f) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        double centroid = 0;
        for (int j = 0; j < 3; ++j) centroid += neutral[3 * static_cast<std::size_t>(tri[3 * f + static_cast<std::size_t>(j)]) + static_cast<std::size_t>(k)] / 3.0;
        d2 += (centroid - c.centre[k]) * (centroid - c.centre[k]);
      }
      if (d2 <= c.radius * c.radius) {
        map[f] = c.value;
        ++covered;
      }
    }
    check(softdeca_avatar_set_parameter_faces(avatar, static_cast<uint32_t>(index), map.data(), static_cast<uint32_t>(map.size())),
          "setting " + c.name + " over a region");
  }
  return covered;
}

struct Timing {
  std::vector<double> call_ms, encoder_ms, blend_ms, hyper_ms, solve_ms, dynamics_ms, normals_ms;
  void add(double call, const softdeca_stats& s) {
    call_ms.push_back(call);
    encoder_ms.push_back(s.encoder_ms);
    blend_ms.push_back(s.blend_ms);
    hyper_ms.push_back(s.hyper_ms);
    solve_ms.push_back(s.solve_ms);
    dynamics_ms.push_back(s.dynamics_ms);
    normals_ms.push_back(s.normals_ms);
  }
  std::string json() const {
    JsonObject o;
    o.number("frames", static_cast<double>(call_ms.size()))
        .number("median_ms", median(call_ms))
        .number("p95_ms", percentile(call_ms, 0.95))
        .number("encoder_median_ms", median(encoder_ms))
        .number("blend_median_ms", median(blend_ms))
        .number("hyper_median_ms", median(hyper_ms))
        .number("solve_median_ms", median(solve_ms))
        .number("dynamics_median_ms", median(dynamics_ms))
        .number("normals_median_ms", median(normals_ms));
    return o.str();
  }
};

// The softdeca_precision that `option`'s value names.
int32_t precision_of(const Options& o, const std::string& option) {
  const std::string p = o.text(option);
  if (p == "default") return SOFTDECA_PRECISION_DEFAULT;
  if (p == "half") return SOFTDECA_PRECISION_HALF;
  if (p == "float") return SOFTDECA_PRECISION_FLOAT;
  if (p == "int8") return SOFTDECA_PRECISION_INT8;
  throw UsageError(option + " must be default, half, float or int8, not '" + p + "'");
}

// The take's frames from --start, at most --frames of them.
Take read_replay_take(const std::string& path, long start, long max_frames, const recording::ReadLimits& limits) {
  if (start < 0 || max_frames < 0) throw UsageError("--start and --frames must not be negative");
  Take take = read_take(path, max_frames ? static_cast<std::size_t>(start + max_frames) : 0, limits);
  if (static_cast<std::size_t>(start) >= take.weights.size())
    throw UsageError("--start " + std::to_string(start) + " is past the take's " + std::to_string(take.weights.size()) + " frames");
  take.weights.erase(take.weights.begin(), take.weights.begin() + start);
  std::fprintf(stderr, "take %s: %zu rows, %zu face-lost rows skipped, %zu unreadable, %zu with weights clamped to [0, 1]; "
               "frames %ld to %zu\n", take.path.c_str(), take.rows, take.face_lost, take.invalid, take.clamped, start,
               static_cast<std::size_t>(start) + take.weights.size() - 1);
  return take;
}

// --models in order, and the localised SoftDECA pass last when --localised is given.
std::vector<std::string> models_to_run(const std::string& list, bool localised) {
  std::vector<std::string> models;
  std::stringstream ss(list);
  std::string m;
  while (std::getline(ss, m, ','))
    if (!m.empty()) models.push_back(m);
  if (localised) models.push_back("softdeca_localised");
  for (const std::string& name : models)
    if (name != "linear" && name != "softdeca" && name != "sparse" && name != "softdeca_localised")
      throw UsageError("unknown model '" + name + "' in --models");
  return models;
}

// One avatar replaying the take, and the buffers its frames are written through.
struct Replay {
  Model& model;
  ReplayAvatar& target;
  const Take& take;
  std::string out;
  long obj_every = 0;
  std::vector<float> vertices, normals, user_face, linear, landmarks;
  softdeca_output output{}, linear_out{};

  Replay(Model& m, ReplayAvatar& a, const Take& t, std::string dir, long every)
      : model(m), target(a), take(t), out(std::move(dir)), obj_every(every) {
    const auto n = static_cast<uint32_t>(target.vertex_count);
    vertices.resize(3 * std::size_t{n});
    normals.resize(3 * std::size_t{n});
    user_face.resize(target.user.neutral.vertices.size());
    linear.resize(3 * std::size_t{n});
    landmarks.resize(3 * model.info.landmark_count);
    output = {sizeof(softdeca_output), vertices.data(), n, normals.data(), n};
    linear_out = {sizeof(softdeca_output), linear.data(), n, nullptr, 0};
  }

  // The tracked face SparseSoftDECA reads for weights w: a user rig blended with the take, or
  // the landmarks of the avatar's own linear blend; returns the point count.
  std::size_t tracked_points(const float* w, const float** points) {
    if (!target.user.empty()) {
      target.user.blend(w, user_face.data());
      *points = user_face.data();
      return target.user.neutral.vertex_count();
    }
    check(softdeca_avatar_evaluate_linear(target.avatar->handle, w, 52, &linear_out), "linear blend");
    if (target.landmarks) target.landmarks->evaluate(linear.data(), landmarks.data());
    else check(softdeca_model_evaluate_landmarks(model.handle, linear.data(), static_cast<uint32_t>(target.vertex_count),
                                                 landmarks.data(), model.info.landmark_count),
               "landmarks");
    *points = landmarks.data();
    return model.info.landmark_count;
  }

  void write_frame_obj(const std::string& name, std::size_t f) {
    make_directories(out + "/obj");
    char file[64];
    std::snprintf(file, sizeof file, "/obj/%s_%05zu.obj", name.c_str(), f);
    target.space->write_obj(out + file, vertices.data(), normals.data(), name + " frame " + std::to_string(f));
  }

  // Every frame of the take through model `name` into <out>/<name>.pc2; returns the timings.
  Timing run(const std::string& name) {
    const bool sparse = name == "sparse";
    softdeca_avatar* avatar = target.avatar->handle;
    if (sparse && !model.info.has_sparse) throw std::runtime_error("the bundle has no SparseSoftDECA model");
    if (!sparse && name != "linear" && !model.info.has_softdeca) throw std::runtime_error("the bundle has no SoftDECA model");
    if (sparse && !target.calibration.empty())
      check(softdeca_avatar_calibrate_landmarks(avatar, target.calibration.data(), static_cast<uint32_t>(target.calibration.size() / 3)),
            "calibration");
    check(softdeca_avatar_reset_dynamics(avatar), "reset dynamics");
    Pc2Writer cache(out + "/" + name + ".pc2", target.vertex_count);
    Timing timing;
    std::fprintf(stderr, "%-18s", name.c_str());
    for (std::size_t f = 0; f < take.weights.size(); ++f) {
      const float* w = take.weights[f].data();
      const float* points = nullptr;
      const std::size_t point_count = sparse ? tracked_points(w, &points) : 0;
      const auto t0 = Clock::now();
      if (name == "linear") check(softdeca_avatar_evaluate_linear(avatar, w, 52, &output), "frame " + std::to_string(f));
      else if (sparse) check(softdeca_avatar_evaluate_landmarks(avatar, points, point_count, &output), "frame " + std::to_string(f));
      else check(softdeca_avatar_evaluate_weights(avatar, w, 52, &output), "frame " + std::to_string(f));
      timing.add(std::chrono::duration<double, std::milli>(Clock::now() - t0).count(), target.avatar->stats());
      cache.add(target.space->to_local(vertices.data()));
      if (obj_every > 0 && f % static_cast<std::size_t>(obj_every) == 0) write_frame_obj(name, f);
      if (f % 200 == 0) std::fprintf(stderr, ".");
    }
    cache.close();
    std::fprintf(stderr, " %zu frames, median %.3f ms/frame\n", timing.call_ms.size(), median(timing.call_ms));
    return timing;
  }
};

// What replay.json says about the avatar: its kind, and for a user's mesh its parts.
std::string avatar_json(const ReplayAvatar& a) {
  JsonObject o;
  o.text("kind", a.kind).number("vertices", static_cast<double>(a.vertex_count));
  if (a.mesh) {
    std::string parts = "[";
    for (const AvatarPart& p : a.mesh->parts) parts += (parts.size() > 1 ? "," : "") + json_string(p.name);
    o.text("mesh", a.mesh->path).raw("parts", parts + "]");
    // How a preview shows it: each part's coordinates to metres in the subject's frame.
    o.raw("view", view_json(*a.mesh, avatar_view(*a.mesh, fit_metres_per_unit(a.fit->report()))));
  }
  if (a.landmarks) o.number("landmarks_max_distance_from_surface", a.landmarks->max_distance());
  return o.str();
}
}  // namespace

int run_replay(const Args& args) {
  Options o("replay", "Replay a take (Live Link Face CSV or a recording) through linear blendshapes, SoftDECA and\n"
                      "SparseSoftDECA onto one avatar; writes <out>/neutral.obj, <model>.pc2 point caches and replay.json (timings).\n"
                      "The avatar: a fit folder (softdeca fit), an avatar folder in the template's topology, or any user's\n"
                      "avatar (glTF, FBX, avatar folder), fitted first (--names, --metres-per-unit, --iterations: as for\n"
                      "softdeca fit). A user's avatar is written as its meshes with ARKit\n"
                      "shapes, each in its own coordinates, in file order. SparseSoftDECA reads landmarks of a tracked face:\n"
                      "the avatar folder's user_face rig blended with the take (as a phone would track it), else the avatar's\n"
                      "own. An ICT identity as avatar: python -m softdeca_train avatar --seed N --out DIR; a contact sheet of\n"
                      "the result: python -m softdeca_train replay-preview --replay OUT.");
  o.positional("TAKE", "Live Link Face CSV (.csv) or a recording of the streaming format");
  o.option("--bundle", "DIR", "model bundle folder or .tar")
      .option("--avatar", "X", "fit folder, avatar folder (neutral.obj, blendshapes/, optional user_face/), or .gltf/.glb/.vrm/.fbx")
      .option("--out", "DIR", "output folder", "out/replay")
      .option("--models", "LIST", "comma-separated: linear, softdeca, sparse", "linear,softdeca,sparse")
      .option("--set", "SPECS", "parameter changes 'name=value' or 'name=value@x,y,z,r' (a region, in the avatar's coordinates), "
                                "';'-separated (value: a number, min, max or default)")
      .option("--localised", "SPEC", "an extra SoftDECA pass with this change 'name=value@x,y,z,r' on top of --set")
      .option("--start", "N", "skip the take's first N frames", "0")
      .option("--frames", "N", "at most N frames of the take after --start (0: all)", "0")
      .option("--threads", "N", "threads per frame (1 or 2)", "1")
      .option("--precision", "P", "SoftDECA's storage (hyper-tensor, vertex and residual stages): default (the "
                                  "library's choice for the model, docs/runtime.md), half, float or int8", "default")
      .option("--sparse-precision", "P", "SparseSoftDECA's hyper-tensor storage: default, half, float or int8", "default")
      .option("--obj-every", "N", "also write every Nth frame as OBJ (0: none)", "0")
      .flag("--dynamics", "enable the second-order dynamics");
  declare_fit_options(o);  // for an avatar fitted now
  declare_read_limits(o);
  if (!o.parse(args)) return 0;
  require_model_inputs(o);
  const std::string out = o.text("--out");
  make_directories(out);
  const unsigned threads = static_cast<unsigned>(o.integer("--threads"));
  const AvatarPrecisions precisions{precision_of(o, "--precision"), precision_of(o, "--sparse-precision")};
  const long start = o.integer("--start");
  const Take take = read_replay_take(o.arg(0), start, o.integer("--frames"), read_limits(o));
  const std::vector<std::string> models = models_to_run(o.text("--models"), o.given("--localised"));
  const std::string avatar_path = o.text("--avatar");

  Model model(o.text("--bundle"));
  ReplayAvatar target = open_replay_avatar(model, avatar_path, shape_names(o), fit_options(o), threads, precisions);
  softdeca_avatar* avatar = target.avatar->handle;
  apply(model, target, parse_changes(o.text("--set")));
  check(softdeca_avatar_set_dynamics(avatar, o.on("--dynamics") ? SOFTDECA_TRUE : SOFTDECA_FALSE), "dynamics");
  check(softdeca_avatar_prepare(avatar), "prepare");
  const double prepare_ms = target.avatar->stats().prepare_ms;

  const float* neutral = target.fitted() ? target.mesh->neutral.data() : target.rig.neutral.vertices.data();
  target.space->write_obj(out + "/neutral.obj", neutral, nullptr, "SoftDECA replay: the avatar's neutral (PC2 caches animate it)");
  Replay replay(model, target, take, out, o.integer("--obj-every"));
  JsonObject timings, files;
  std::size_t localised_faces = 0;
  for (const std::string& name : models) {
    if (name == "softdeca_localised") {
      localised_faces = apply(model, target, parse_changes(o.text("--localised")));
      check(softdeca_avatar_prepare(avatar), "prepare (localised)");
    }
    timings.raw(name, replay.run(name).json());
    files.text(name, out + "/" + name + ".pc2");
  }
  JsonObject summary;
  summary.text("take", take.path)
      .number("take_rows", static_cast<double>(take.rows))
      .number("first_frame", static_cast<double>(start))
      .number("frames", static_cast<double>(take.weights.size()))
      .number("face_lost_rows_skipped", static_cast<double>(take.face_lost))
      .number("unreadable_rows_skipped", static_cast<double>(take.invalid))
      .number("clamped_rows", static_cast<double>(take.clamped))
      .number("take_median_frame_s", take.median_frame_s)
      .text("bundle", o.text("--bundle"))
      .raw("untrained", model.info.untrained ? "true" : "false")
      .text("avatar", avatar_path)
      .raw("avatar_mesh", avatar_json(target))
      .raw("landmarks_from", json_string(!target.user.empty() ? "the user_face rig blended with the take"
                                         : target.fitted()    ? "the bundle's landmarks carried onto the avatar's linear blend (calibrated at rest)"
                                                              : "the avatar's linear blend"))
      .raw("dynamics", o.on("--dynamics") ? "true" : "false")
      .number("threads", threads)
      .text("precision", o.text("--precision"))
      .text("sparse_precision", o.text("--sparse-precision"))
      .text("set", o.text("--set"))
      .text("localised", o.text("--localised"))
      .number("localised_faces", static_cast<double>(localised_faces))
      .number("prepare_ms", prepare_ms)
      .text("neutral", out + "/neutral.obj")
      .raw("point_caches", files.str())
      .raw("timings", timings.str(true));
  write_text_file(out + "/replay.json", summary.str(true) + "\n");
  std::printf("wrote %s/neutral.obj, %zu point caches (.pc2) and %s/replay.json\n", out.c_str(), models.size(), out.c_str());
  return 0;
}
}  // namespace softdeca::cli
