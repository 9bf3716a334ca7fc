// softdeca fit: fits a user's own ARKit-rigged avatar (glTF, FBX or an avatar folder, any
// topology) to a bundle's template once, through the C ABI (softdeca_avatar_fit_create), and
// writes the fit folder `softdeca replay --avatar DIR` and Unity read (fit_folder.h): the fit,
// its report with what the file gave, and a picture of the template on the avatar. A fit the
// library judges poor (its report's "quality") is refused unless --keep-poor-fit is given.
#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "imported_avatar.h"
#include "avatar_view.h"
#include "bundle/json.h"
#include "command.h"
#include "fit_verdict.h"
#include "fit_folder.h"
#include "fit_options_arg.h"
#include "fit_picture.h"
#include "options.h"
#include "runtime_session.h"
#include "staged_folder.h"

namespace softdeca::cli {

namespace {
// One line per fact on stderr: what was read, what was left out and why.
void describe(const AvatarFile& a) {
  std::fprintf(stderr, "%s (%s): %zu vertices, %zu triangles, %zu of 52 ARKit shapes\n", a.path.c_str(), a.format.c_str(),
               a.vertex_count(), a.triangles.size() / 3, a.shape_count());
  for (const AvatarPart& p : a.parts) std::fprintf(stderr, "  included  %-24s %zu vertices\n", p.name.c_str(), p.vertex_count);
  for (const LeftOutMesh& m : a.left_out)
    std::fprintf(stderr, "  left out  %-24s %zu vertices: %s\n", m.name.c_str(), m.vertex_count, m.reason.c_str());
  if (!a.names_not_used.empty()) std::fprintf(stderr, "  %zu shape names not used (listed in fit.json)\n", a.names_not_used.size());
  if (!a.declared_unit.empty()) std::fprintf(stderr, "  the file declares its unit: %s\n", a.declared_unit.c_str());
}

// The picture's axes: the subject's frame as the library reads it off the avatar's shapes.
PictureAxes picture_axes(const AvatarFile& a) {
  const AvatarView view = avatar_view(a, 1.0);
  PictureAxes axes{};
  for (int k = 0; k < 3; ++k) {
    axes.left[k] = view.left[k];
    axes.up[k] = view.up[k];
    axes.forward[k] = view.forward[k];
  }
  return axes;
}

// fit.png's bytes: the registered template on the avatar.
std::string draw(const Model& model, const Fit& fit, const AvatarFile& a) {
  const std::vector<float> registered = fit.registered(model);
  std::vector<std::int32_t> skin(3 * std::size_t{model.info.skin_triangle_count});
  check(softdeca_model_get_skin_triangles(model.handle, skin.data(), model.info.skin_triangle_count), "skin triangles");
  const PictureMesh avatar{a.neutral.data(), a.vertex_count(), a.triangles.data(), a.triangles.size() / 3};
  const PictureMesh templ{registered.data(), model.info.skin_vertex_count, skin.data(), model.info.skin_triangle_count};
  return fit_picture_png(avatar, templ, picture_axes(a));
}

}  // namespace

int run_fit(const Args& args) {
  Options o("fit", "Fit a user's own ARKit-rigged avatar (any topology, a head or a whole body, any unit and axes) to a\n"
                   "bundle's template once. MESH: a glTF 2.0 file (.gltf, .glb, .vrm), an FBX file, or an avatar folder\n"
                   "(neutral.obj and blendshapes/<name>.obj, one OBJ per shape in the neutral's vertex order). The meshes\n"
                   "with at least one ARKit shape are fitted, each placed by its node's transform; meshes without one (hair,\n"
                   "clothes) are listed and left out. Shape names follow the product's rule (eyeBlinkLeft,\n"
                   "blendShape1.eyeBlinkLeft, AK_07_EyeBlinkLeft, eyeBlink_L, mouth_smile_l, ...; docs/avatars.md) unless\n"
                   "--names maps them. Writes DIR/avatar.fit, DIR/fit.json (the fit's report, the parts, each ARKit shape's\n"
                   "rig names, the names not used) and DIR/fit.png (front and side views: the template in colour on the\n"
                   "avatar). Then: softdeca replay TAKE --bundle B --avatar DIR.");
  o.positional("MESH", "the avatar: .gltf, .glb, .vrm, .fbx, or an avatar folder");
  o.option("--bundle", "DIR", "model bundle folder or .tar (with the template head)")
      .option("--out", "DIR", "the fit folder to write (new, or an earlier fit folder: replaced whole)");
  o.flag("--keep-poor-fit", "write a fit that fails the library's quality bounds (docs/avatars.md) anyway, marked poor in fit.json");
  declare_fit_options(o);
  if (!o.parse(args)) return 0;
  if (!o.given("--bundle")) throw UsageError("--bundle is required");
  if (!o.given("--out")) throw UsageError("--out is required");
  const softdeca_fit_options options = fit_options(o);
  const std::string out = o.text("--out");

  std::fprintf(stderr, "reading %s\n", o.arg(0).c_str());
  const AvatarFile avatar = read_avatar_file(o.arg(0), shape_names(o));
  describe(avatar);
  std::fprintf(stderr, "loading %s\n", o.text("--bundle").c_str());
  Model model(o.text("--bundle"));
  std::fprintf(stderr, "fitting the template to %zu vertices\n", avatar.vertex_count());
  const auto t0 = std::chrono::steady_clock::now();
  const Fit fit(model, avatar.abi_mesh(), options);
  std::fprintf(stderr, "fitted in %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  const std::string report = fit.report();
  const Verdict verdict = read_verdict(report);
  if (!verdict.passed) {
    if (!o.on("--keep-poor-fit"))
      throw std::runtime_error("the fit is poor (" + verdict.measure + "): " + verdict.reason +
                               " Nothing was written; --keep-poor-fit writes it anyway, marked poor in fit.json.");
    std::fprintf(stderr, "keeping a poor fit (%s): %s\n", verdict.measure.c_str(), verdict.reason.c_str());
  }

  // Written whole beside DIR and renamed into place: DIR is the previous fit folder or this one.
  StagedFolder folder(out, fit_folder_files());
  fit.save(fit_file(folder.path()));
  folder.write("fit.json", fit_json(avatar, out, report, !verdict.passed));
  std::fprintf(stderr, "drawing %s/fit.png\n", out.c_str());
  folder.write("fit.png", draw(model, fit, avatar));
  folder.commit();
  std::printf("wrote %s/avatar.fit, %s/fit.json and %s/fit.png\n", out.c_str(), out.c_str(), out.c_str());
  return 0;
}

}  // namespace softdeca::cli
