// softdeca replay: a take (Live Link Face CSV or recording) through plain linear blendshapes, SoftDECA (from the weights) and
// SparseSoftDECA (from landmarks) onto one avatar. Writes per model a PC2 point cache over the
// avatar's neutral OBJ (Blender: import neutral.obj, add a Mesh Cache modifier; Unity: the OBJ
// sequence of --obj-every) and replay.json with the timing summary. Native end to end: the avatar
// (e.g. an ICT identity: python -m softdeca_train avatar) and the contact sheet of the output
// (python -m softdeca_train replay-preview) come from the training package, before and after.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "command.h"
#include "json.h"
#include "mesh_io.h"
#include "options.h"
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

// Applies changes; returns the number of skin faces a regional change covered.
std::size_t apply(const Model& model, Avatar& avatar, const ObjMesh& neutral, const std::vector<Change>& changes) {
  std::size_t covered = 0;
  std::vector<std::int32_t> tri(3 * model.info.skin_triangle_count);
  check(softdeca_model_get_skin_triangles(model.handle, tri.data(), model.info.skin_triangle_count), "skin triangles");
  for (Change c : changes) {
    const int index = model.parameter(c.name);
    if (!c.bound.empty()) {
      softdeca_parameter_info info{};
      info.struct_size = sizeof info;
      check(softdeca_model_get_parameter(model.handle, static_cast<uint32_t>(index), &info), "parameter " + c.name);
      c.value = static_cast<float>(c.bound == "min" ? info.lo : c.bound == "max" ? info.hi : info.default_value);
      std::fprintf(stderr, "%s=%s: %g\n", c.name.c_str(), c.bound.c_str(), static_cast<double>(c.value));
    }
    if (!c.region) {
      check(softdeca_avatar_set_parameter(avatar.handle, static_cast<uint32_t>(index), c.value), "setting " + c.name);
      continue;
    }
    double current = 0;
    check(softdeca_avatar_get_parameter(avatar.handle, static_cast<uint32_t>(index), &current, nullptr), "parameter");
    std::vector<float> map(model.info.skin_triangle_count, static_cast<float>(current));
    for (std::size_t f = 0; f < map.size(); ++f) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        double centroid = 0;
        for (int j = 0; j < 3; ++j) centroid += neutral.vertices[3 * static_cast<std::size_t>(tri[3 * f + static_cast<std::size_t>(j)]) + static_cast<std::size_t>(k)] / 3.0;
        d2 += (centroid - c.centre[k]) * (centroid - c.centre[k]);
      }
      if (d2 <= c.radius * c.radius) {
        map[f] = c.value;
        ++covered;
      }
    }
    check(softdeca_avatar_set_parameter_faces(avatar.handle, static_cast<uint32_t>(index), map.data(), static_cast<uint32_t>(map.size())),
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

unsigned precision_of(const std::string& p) {
  if (p == "half") return SOFTDECA_PRECISION_HALF;
  if (p == "float") return SOFTDECA_PRECISION_FLOAT;
  if (p == "int8") return SOFTDECA_PRECISION_INT8;
  throw UsageError("--precision must be half, float or int8");
}

// The take's frames from --start, at most --frames of them.
Take read_replay_take(const std::string& path, long start, long max_frames) {
  if (start < 0 || max_frames < 0) throw UsageError("--start and --frames must not be negative");
  Take take = read_take(path, max_frames ? static_cast<std::size_t>(start + max_frames) : 0);
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
  Avatar& avatar;
  const FaceRig& rig;
  const FaceRig& user;
  const Take& take;
  std::string out;
  long obj_every = 0;
  std::vector<float> vertices, normals, user_face, linear, landmarks;
  softdeca_output output{}, linear_out{};

  Replay(Model& m, Avatar& a, const FaceRig& r, const FaceRig& u, const Take& t, std::string dir, long every)
      : model(m), avatar(a), rig(r), user(u), take(t), out(std::move(dir)), obj_every(every) {
    const uint32_t vh = model.info.head_vertex_count;
    vertices.resize(vh * 3);
    normals.resize(vh * 3);
    user_face.resize(user.neutral.vertices.size());
    linear.resize(vh * 3);
    landmarks.resize(3 * model.info.landmark_count);
    output = {sizeof(softdeca_output), vertices.data(), vh, normals.data(), vh};
    linear_out = {sizeof(softdeca_output), linear.data(), vh, nullptr, 0};
  }

  // The tracked face SparseSoftDECA reads for weights w: a user rig blended with the take, or
  // the avatar's own landmarks; returns the point count.
  std::size_t tracked_points(const float* w, const float** points) {
    if (!user.empty()) {
      user.blend(w, user_face.data());
      *points = user_face.data();
      return user.neutral.vertex_count();
    }
    const uint32_t vh = model.info.head_vertex_count;
    check(softdeca_avatar_evaluate_linear(avatar.handle, w, 52, &linear_out), "linear blend");
    check(softdeca_model_evaluate_landmarks(model.handle, linear.data(), vh, landmarks.data(), model.info.landmark_count),
          "landmarks");
    *points = landmarks.data();
    return model.info.landmark_count;
  }

  void write_frame_obj(const std::string& name, std::size_t f) {
    make_directories(out + "/obj");
    char file[64];
    std::snprintf(file, sizeof file, "/obj/%s_%05zu.obj", name.c_str(), f);
    write_obj(out + file, vertices.data(), model.info.head_vertex_count, normals.data(), rig.neutral.triangles.data(),
              rig.neutral.triangles.size() / 3, name + " frame " + std::to_string(f));
  }

  // Every frame of the take through model `name` into <out>/<name>.pc2; returns the timings.
  Timing run(const std::string& name) {
    const bool sparse = name == "sparse";
    if (sparse && !model.info.has_sparse) throw std::runtime_error("the bundle has no SparseSoftDECA model");
    if (!sparse && name != "linear" && !model.info.has_softdeca) throw std::runtime_error("the bundle has no SoftDECA model");
    if (sparse && !user.empty())
      check(softdeca_avatar_calibrate_landmarks(avatar.handle, user.neutral.vertices.data(), user.neutral.vertex_count()),
            "calibration");
    check(softdeca_avatar_reset_dynamics(avatar.handle), "reset dynamics");
    Pc2Writer cache(out + "/" + name + ".pc2", model.info.head_vertex_count);
    Timing timing;
    std::fprintf(stderr, "%-18s", name.c_str());
    for (std::size_t f = 0; f < take.weights.size(); ++f) {
      const float* w = take.weights[f].data();
      const float* points = nullptr;
      const std::size_t point_count = sparse ? tracked_points(w, &points) : 0;
      const auto t0 = Clock::now();
      if (name == "linear") check(softdeca_avatar_evaluate_linear(avatar.handle, w, 52, &output), "frame " + std::to_string(f));
      else if (sparse) check(softdeca_avatar_evaluate_landmarks(avatar.handle, points, point_count, &output), "frame " + std::to_string(f));
      else check(softdeca_avatar_evaluate_weights(avatar.handle, w, 52, &output), "frame " + std::to_string(f));
      timing.add(std::chrono::duration<double, std::milli>(Clock::now() - t0).count(), avatar.stats());
      cache.add(vertices.data());
      if (obj_every > 0 && f % static_cast<std::size_t>(obj_every) == 0) write_frame_obj(name, f);
      if (f % 200 == 0) std::fprintf(stderr, ".");
    }
    cache.close();
    std::fprintf(stderr, " %zu frames, median %.3f ms/frame\n", timing.call_ms.size(), median(timing.call_ms));
    return timing;
  }
};
}  // namespace

int run_replay(const Args& args) {
  Options o("replay", "Replay a take (Live Link Face CSV or a recording) through linear blendshapes, SoftDECA and\n"
                      "SparseSoftDECA onto one avatar; writes <out>/neutral.obj, <model>.pc2 point caches and replay.json (timings).\n"
                      "SparseSoftDECA reads landmarks of a tracked face: the avatar's user_face rig blended with the\n"
                      "take (as a phone would track it), else the avatar's own. An ICT identity as avatar:\n"
                      "python -m softdeca_train avatar --seed N --out DIR; a contact sheet of the result:\n"
                      "python -m softdeca_train replay-preview --replay OUT.");
  o.positional("TAKE", "Live Link Face CSV (.csv) or a recording of the streaming format");
  declare_model_inputs(o);
  o.option("--out", "DIR", "output folder", "out/replay")
      .option("--models", "LIST", "comma-separated: linear, softdeca, sparse", "linear,softdeca,sparse")
      .option("--set", "SPECS", "parameter changes 'name=value' or 'name=value@x,y,z,r' (a region), ';'-separated (value: a number, min, max or default)")
      .option("--localised", "SPEC", "an extra SoftDECA pass with this change 'name=value@x,y,z,r' on top of --set")
      .option("--start", "N", "skip the take's first N frames", "0")
      .option("--frames", "N", "at most N frames of the take after --start (0: all)", "0")
      .option("--threads", "N", "threads per frame (1 or 2)", "1")
      .option("--precision", "P", "hyper-tensor storage: half, float or int8", "half")
      .option("--obj-every", "N", "also write every Nth frame as OBJ (0: none)", "0")
      .flag("--dynamics", "enable the second-order dynamics");
  if (!o.parse(args)) return 0;
  require_model_inputs(o);
  const std::string out = o.text("--out");
  make_directories(out);
  const unsigned threads = static_cast<unsigned>(o.integer("--threads"));
  const unsigned precision = precision_of(o.text("--precision"));
  const long start = o.integer("--start");
  const Take take = read_replay_take(o.arg(0), start, o.integer("--frames"));
  const std::vector<std::string> models = models_to_run(o.text("--models"), o.given("--localised"));
  const std::string avatar_dir = o.text("--avatar");
  const FaceRig rig = read_rig(avatar_dir);
  const FaceRig user = read_rig(avatar_dir + "/user_face", true);

  Model model(o.text("--bundle"));
  const uint32_t vh = model.info.head_vertex_count;
  if (rig.neutral.vertex_count() != vh)
    throw std::runtime_error(avatar_dir + "/neutral.obj has " + std::to_string(rig.neutral.vertex_count()) +
                             " vertices; the bundle's template has " + std::to_string(vh));
  Avatar avatar(model, rig.neutral, rig.deltas, threads, precision);
  apply(model, avatar, rig.neutral, parse_changes(o.text("--set")));
  check(softdeca_avatar_set_dynamics(avatar.handle, o.on("--dynamics") ? SOFTDECA_TRUE : SOFTDECA_FALSE), "dynamics");
  check(softdeca_avatar_prepare(avatar.handle), "prepare");
  const double prepare_ms = avatar.stats().prepare_ms;

  write_obj(out + "/neutral.obj", rig.neutral.vertices.data(), vh, nullptr, rig.neutral.triangles.data(),
            rig.neutral.triangles.size() / 3, "SoftDECA replay: the avatar's neutral (PC2 caches animate it)");
  Replay replay(model, avatar, rig, user, take, out, o.integer("--obj-every"));
  JsonObject timings, files;
  std::size_t localised_faces = 0;
  for (const std::string& name : models) {
    if (name == "softdeca_localised") {
      localised_faces = apply(model, avatar, rig.neutral, parse_changes(o.text("--localised")));
      check(softdeca_avatar_prepare(avatar.handle), "prepare (localised)");
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
      .text("avatar", avatar_dir)
      .raw("landmarks_from", json_string(user.empty() ? "the avatar's linear blend" : "the user_face rig blended with the take"))
      .raw("dynamics", o.on("--dynamics") ? "true" : "false")
      .number("threads", threads)
      .text("precision", o.text("--precision"))
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
