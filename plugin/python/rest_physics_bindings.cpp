// Python binding of the physics at prepare (prepare/rest_physics.h): the runtime's own solve of
// an avatar's head at rest, so that what the training package learns from (the rest changes
// of its data, softdeca_train/train/rest_changes.py) is computed by the code the runtime adds
// to every frame. The parameters reach it through prepare::ParameterState, the runtime's.
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <memory>
#include <string>
#include <vector>

#include "bundle/manifest.h"
#include "prepare/parameters.h"
#include "prepare/rest_head.h"
#include "prepare/rest_physics.h"
#include "runtime/deformation_transfer.h"

namespace nb = nanobind;
using namespace softdeca;

namespace {
using HeadF = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// One avatar's head under the bundle's physics at prepare. RestPhysics keeps references to the
// head and the manifest, which live as long as it.
class RestPhysicsBinding {
 public:
  RestPhysicsBinding(const std::string& manifest_json, const nb::bytes& rest_head, const HeadF& neutral_head,
                     const Triangles& skin_triangles, int threads)
      : manifest_(bundle::parse_manifest(manifest_json)) {
    if (!manifest_.has_rest_physics) throw nb::value_error("the manifest has no physics at prepare (rest_physics)");
    const auto* p = static_cast<const std::uint8_t*>(rest_head.data());
    head_ = prepare::parse_rest_head(manifest_, bundle::Bytes(p, p + rest_head.size()));
    if (neutral_head.rows() != manifest_.head_vertices)
      throw nb::value_error(
          ("neutral_head needs the bundle's " + std::to_string(manifest_.head_vertices) + " head vertices").c_str());
    if (skin_triangles.rows() != manifest_.skin_triangles)
      throw nb::value_error("skin_triangles must be the bundle's skin triangles");
    if (skin_triangles.size() > 0 && (skin_triangles.minCoeff() < 0 || skin_triangles.maxCoeff() >= manifest_.skin_vertices))
      throw nb::value_error("skin_triangles name a vertex outside the skin");
    neutral_.assign(neutral_head.data(), neutral_head.data() + neutral_head.size());
    triangles_.assign(skin_triangles.data(), skin_triangles.data() + skin_triangles.size());
    area_ = runtime::SkinGeometry::measure(neutral_.data(), static_cast<std::size_t>(manifest_.skin_vertices), triangles_)
                .face_area;
    physics_ = std::make_unique<prepare::RestPhysics>(head_, manifest_, neutral_.data(), triangles_, threads);
  }

  // The skin at rest (skin_vertices x 3) under global values (one per manifest parameter) and,
  // where `localised` says so, per-vertex maps (skin_vertices x parameters).
  sim::Positions solve(const Eigen::VectorXd& globals, const Rows& vertex_maps, const Eigen::VectorXi& localised) {
    const auto n = static_cast<Eigen::Index>(manifest_.parameters.size());
    if (globals.size() != n || localised.size() != n)
      throw nb::value_error(("globals and localised need one value per parameter (" + std::to_string(n) + ")").c_str());
    if (localised.any() && (vertex_maps.rows() != manifest_.skin_vertices || vertex_maps.cols() != n))
      throw nb::value_error("vertex_maps must be skin_vertices x parameters where a parameter is localised");
    prepare::ParameterState state(manifest_, triangles_, area_);
    std::vector<float> column(static_cast<std::size_t>(manifest_.skin_vertices));
    for (Eigen::Index k = 0; k < n; ++k) {
      state.set_global(static_cast<int>(k), globals[k]);
      if (!localised[k]) continue;
      for (Eigen::Index v = 0; v < vertex_maps.rows(); ++v) column[static_cast<std::size_t>(v)] = static_cast<float>(vertex_maps(v, k));
      state.set_vertices(static_cast<int>(k), column.data(), column.size());
    }
    return physics_->solve(state);
  }

  int iterations() const { return physics_->iterations(); }

 private:
  bundle::Manifest manifest_;
  prepare::RestHead head_;
  std::vector<std::int32_t> triangles_;
  std::vector<float> neutral_;
  std::vector<double> area_;
  std::unique_ptr<prepare::RestPhysics> physics_;
};
}  // namespace

void bind_rest_physics(nb::module_& m) {
  nb::class_<RestPhysicsBinding>(m, "RestPhysics",
                                 "One avatar's head at rest under a bundle's physics at prepare: the runtime's solve.")
      .def(nb::init<const std::string&, const nb::bytes&, const HeadF&, const Triangles&, int>(),
           nb::arg("manifest_json"), nb::arg("rest_head"), nb::arg("neutral_head"), nb::arg("skin_triangles"),
           nb::arg("threads") = 1,
           "manifest_json: the bundle's manifest.json text; rest_head: its rest_head.bin bytes (checked as the runtime "
           "checks them); neutral_head: the avatar's whole head (head_vertices x 3, metres); skin_triangles: the "
           "bundle's. Carries the fill to the neutral and builds the simulator. ValueError naming the first problem, "
           "also when the carried head has an inverted tet (the runtime's prepare refuses that head too).")
      .def("solve", &RestPhysicsBinding::solve, nb::arg("globals"), nb::arg("vertex_maps"), nb::arg("localised"),
           "The skin at rest (skin_vertices x 3) under the parameters: globals (one per manifest parameter), and "
           "vertex_maps' column k where localised[k] is non-zero.")
      .def_prop_ro("iterations", &RestPhysicsBinding::iterations, "The last solve's iterations.");
}
