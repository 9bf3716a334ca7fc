#include "replay_avatar.h"

#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "fit_folder.h"
#include "fit_verdict.h"

namespace softdeca::cli {

namespace {
bool template_topology(const Model& model, const std::string& path) {
  if (is_fit_folder(path) || !file_exists(path + "/neutral.obj")) return false;
  return read_avatar_obj(path, "neutral.obj").vertex_count() == model.info.head_vertex_count;
}

void open_template(const Model& model, const std::string& path, unsigned threads, AvatarPrecisions precisions,
                   ReplayAvatar& a) {
  a.kind = "template topology";
  a.rig = read_rig(path);
  a.vertex_count = model.info.head_vertex_count;
  a.avatar = std::make_unique<Avatar>(model, a.rig.neutral, a.rig.deltas, threads, precisions);
  AvatarPart whole{"avatar", 0, a.vertex_count, 0, a.rig.neutral.triangles.size() / 3, {}, false};
  const double identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::copy(identity, identity + 16, whole.transform);
  a.space = std::make_unique<PartSpace>(std::vector<AvatarPart>{whole}, a.rig.neutral.triangles, a.vertex_count);
  a.map_vertices = a.rig.neutral.vertices;
  a.map_triangles.resize(3 * std::size_t{model.info.skin_triangle_count});
  check(softdeca_model_get_skin_triangles(model.handle, a.map_triangles.data(), model.info.skin_triangle_count), "skin triangles");
}

void open_fitted(const Model& model, const std::string& path, const ShapeNames& names, const softdeca_fit_options& options,
                 unsigned threads, AvatarPrecisions precisions, ReplayAvatar& a) {
  if (is_fit_folder(path)) {
    a.kind = "fit folder";
    a.mesh = std::make_unique<AvatarFile>(read_fitted_mesh(path));
    a.fit = std::make_unique<Fit>(model, fit_file(path));
    const Verdict verdict = read_verdict(a.fit->report());
    if (!verdict.passed)  // kept with softdeca fit --keep-poor-fit: the user chose it, and is told
      std::fprintf(stderr, "warning: %s holds a poor fit (%s): %s\n", path.c_str(), verdict.measure.c_str(), verdict.reason.c_str());
  } else {
    a.kind = "fitted now";
    a.mesh = std::make_unique<AvatarFile>(read_avatar_file(path, names));
    std::fprintf(stderr, "fitting %s (%zu vertices; softdeca fit saves a fit to reuse)\n", path.c_str(), a.mesh->vertex_count());
    a.fit = std::make_unique<Fit>(model, a.mesh->abi_mesh(), options);
    const Verdict verdict = read_verdict(a.fit->report());
    if (!verdict.passed)
      throw std::runtime_error("the fit of " + path + " is poor (" + verdict.measure + "): " + verdict.reason +
                               " To replay it anyway: softdeca fit " + path + " --keep-poor-fit --out DIR, then --avatar DIR.");
  }
  a.vertex_count = a.mesh->vertex_count();
  a.avatar = std::make_unique<Avatar>(model, *a.fit, a.mesh->abi_mesh(), threads, precisions);
  a.space = std::make_unique<PartSpace>(*a.mesh);
  a.map_vertices = a.mesh->neutral;
  a.map_triangles = a.mesh->triangles;
  // The bundle's landmarks on the registered template, carried onto the user's surface.
  const std::vector<float> registered = a.fit->registered(model);
  std::vector<float> landmarks(3 * std::size_t{model.info.landmark_count});
  check(softdeca_model_evaluate_landmarks(model.handle, registered.data(), model.info.skin_vertex_count, landmarks.data(),
                                          model.info.landmark_count),
        "landmarks on the registered template");
  a.landmarks = std::make_unique<SurfacePoints>(a.mesh->neutral.data(), a.vertex_count, a.mesh->triangles, landmarks.data(),
                                                model.info.landmark_count);
}
}  // namespace

ReplayAvatar open_replay_avatar(const Model& model, const std::string& path, const ShapeNames& names,
                                const softdeca_fit_options& options, unsigned threads, AvatarPrecisions precisions) {
  ReplayAvatar a;
  if (template_topology(model, path)) open_template(model, path, threads, precisions, a);
  else open_fitted(model, path, names, options, threads, precisions, a);
  a.user = read_rig(path, "user_face", true);
  if (a.user.empty() && a.kind == "fit folder") a.user = read_rig(a.mesh->path, "user_face", true);  // beside the fitted mesh
  if (!a.user.empty()) {
    a.calibration = a.user.neutral.vertices;
  } else if (a.landmarks) {
    a.calibration.resize(3 * a.landmarks->size());
    a.landmarks->evaluate(a.mesh->neutral.data(), a.calibration.data());
  }
  return a;
}

}  // namespace softdeca::cli
