#include "runtime_session.h"

#include <sys/stat.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "input_files.h"
#include "stream/arkit_names.h"

namespace softdeca::cli {

void check(softdeca_status status, const std::string& what) {
  if (status != SOFTDECA_OK)
    throw std::runtime_error(what + ": " + softdeca_status_name(status) + ": " + softdeca_last_error());
}

Model::Model(const std::string& bundle, unsigned prepare_threads) {
  softdeca_model_options opts{sizeof(softdeca_model_options), prepare_threads, 0};
  check(softdeca_model_load(bundle.c_str(), &opts, &handle), "loading " + bundle);
  info.struct_size = sizeof info;
  check(softdeca_model_get_info(handle, &info), "model info");
}

int Model::parameter(const std::string& name) const {
  uint32_t i = 0;
  check(softdeca_model_find_parameter(handle, name.c_str(), &i), "parameter " + name);
  return static_cast<int>(i);
}

Avatar::Avatar(const Model& model, const ObjMesh& neutral, const std::vector<float>& deltas, unsigned threads,
               AvatarPrecisions precisions) {
  softdeca_avatar_mesh mesh{};
  mesh.struct_size = sizeof mesh;
  mesh.neutral = neutral.vertices.data();
  mesh.vertex_count = static_cast<uint32_t>(neutral.vertex_count());
  mesh.triangles = neutral.triangles.data();
  mesh.triangle_count = static_cast<uint32_t>(neutral.triangles.size() / 3);
  mesh.blendshapes = deltas.empty() ? nullptr : deltas.data();
  mesh.blendshape_count = deltas.empty() ? 0 : 52;
  create(model, mesh, nullptr, threads, precisions);
}

Avatar::Avatar(const Model& model, const Fit& fit, const softdeca_avatar_mesh& mesh, unsigned threads,
               AvatarPrecisions precisions) {
  create(model, mesh, fit.handle, threads, precisions);
}

void Avatar::create(const Model& model, const softdeca_avatar_mesh& mesh, const softdeca_avatar_fit* fit, unsigned threads,
                    AvatarPrecisions precisions) {
  softdeca_avatar_desc d{};
  d.struct_size = sizeof d;
  d.mesh = &mesh;
  d.fit = fit;
  d.threads = threads;
  d.precision = precisions.softdeca;
  d.sparse_precision = precisions.sparse;
  check(softdeca_avatar_create(model.handle, &d, &handle), fit ? "creating the fitted avatar" : "creating the avatar");
}

Fit::Fit(const Model& model, const softdeca_avatar_mesh& mesh, const softdeca_fit_options& options) {
  check(softdeca_avatar_fit_create(model.handle, &mesh, &options, &handle), "fitting the avatar");
}

Fit::Fit(const Model& model, const std::string& path) {
  check(softdeca_avatar_fit_load(model.handle, path.c_str(), &handle), "loading the fit " + path);
}

void Fit::save(const std::string& path) const { check(softdeca_avatar_fit_save(handle, path.c_str()), "saving the fit " + path); }

std::string Fit::report() const {
  std::string text(1 << 16, '\0');
  uint32_t length = 0;
  softdeca_status status = softdeca_avatar_fit_get_report(handle, &text[0], static_cast<uint32_t>(text.size()), &length);
  if (status == SOFTDECA_ERROR_BUFFER_TOO_SMALL) {
    text.assign(std::size_t{length} + 1, '\0');
    status = softdeca_avatar_fit_get_report(handle, &text[0], static_cast<uint32_t>(text.size()), &length);
  }
  check(status, "the fit's report");
  text.resize(length);
  return text;
}

std::vector<float> Fit::registered(const Model& model) const {
  std::vector<float> points(3 * std::size_t{model.info.skin_vertex_count});
  check(softdeca_avatar_fit_get_registered(handle, points.data(), model.info.skin_vertex_count, nullptr), "the registered template");
  return points;
}

softdeca_stats Avatar::stats() const {
  softdeca_stats s{};
  s.struct_size = sizeof s;
  check(softdeca_avatar_get_stats(handle, &s), "stats");
  return s;
}

void FaceRig::blend(const float* w, float* out) const {
  const std::size_t n = neutral.vertices.size();
  std::copy(neutral.vertices.begin(), neutral.vertices.end(), out);
  for (std::size_t s = 0; s < 52; ++s) {
    if (w[s] == 0.0f) continue;
    const float* d = deltas.data() + s * n;
    for (std::size_t i = 0; i < n; ++i) out[i] += w[s] * d[i];
  }
}

bool file_exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

void make_directories(const std::string& path) {
  std::string partial;
  for (std::size_t i = 0; i <= path.size(); ++i) {
    if (i == path.size() || path[i] == '/') {
      if (!partial.empty() && !file_exists(partial) && ::mkdir(partial.c_str(), 0755) != 0 && !file_exists(partial))
        throw std::runtime_error("cannot create " + partial);
    }
    if (i < path.size()) partial += path[i];
  }
}

ObjMesh read_avatar_obj(const std::string& dir, const std::string& relative) {
  const avatar_import::InputFolder folder(dir);
  return avatar_import::parse_obj(folder.read(relative, avatar_import::ImportLimits{}.max_file_bytes, "an OBJ file"),
                                  dir + "/" + relative);
}

FaceRig read_rig(const std::string& dir, const std::string& sub, bool optional) {
  FaceRig rig;
  const std::string at = sub.empty() ? "" : sub + "/";
  if (optional && !file_exists(dir + "/" + at + "neutral.obj")) return rig;
  rig.neutral = read_avatar_obj(dir, at + "neutral.obj");
  const std::size_t n = rig.neutral.vertices.size();
  rig.deltas.assign(52 * n, 0.0f);
  for (std::size_t s = 0; s < 52; ++s) {
    const std::string relative = at + "blendshapes/" + stream::blendshape_name(s) + ".obj";
    if (!file_exists(dir + "/" + relative)) continue;
    const ObjMesh shape = read_avatar_obj(dir, relative);
    if (shape.vertices.size() != n) throw std::runtime_error(dir + "/" + relative + ": vertex count differs from the neutral");
    for (std::size_t i = 0; i < n; ++i) rig.deltas[s * n + i] = shape.vertices[i] - rig.neutral.vertices[i];
    ++rig.present;
  }
  return rig;
}

double median(std::vector<double> v) { return percentile(std::move(v), 0.5); }

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

void declare_model_inputs(Options& o) {
  o.option("--bundle", "DIR", "model bundle folder or .tar")
      .option("--avatar", "DIR", "avatar folder (neutral.obj, blendshapes/, optional user_face/)");
}

void require_model_inputs(const Options& o) {
  if (!o.given("--bundle")) throw UsageError("--bundle is required");
  if (!o.given("--avatar")) throw UsageError("--avatar is required (python -m softdeca_train avatar writes one)");
}

}  // namespace softdeca::cli
