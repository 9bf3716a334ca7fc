// Python bindings of the native library's C++ internals (not the C ABI: numpy arrays go in and
// out without copies through Eigen). Imported as `softdeca_native`.
#include <nanobind/eigen/dense.h>
#include <nanobind/eigen/sparse.h>
#include <nanobind/nanobind.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "geometry/cotan.h"
#include "geometry/intersections.h"
#include "geometry/tet_mesh.h"
#include "stream/rig_names.h"

namespace nb = nanobind;
using namespace softdeca::geometry;

void bind_sim(nb::module_& m);  // sim_bindings.cpp: the physics simulator
void bind_fit(nb::module_& m);  // fit_bindings.cpp: fitting a user's avatar
void bind_prepare(nb::module_& m);  // prepare_bindings.cpp: the contact rules
void bind_rest_physics(nb::module_& m);  // rest_physics_bindings.cpp: the physics at prepare

NB_MODULE(softdeca_native, m) {
  m.doc() = "SoftDECA native geometry (C++), used by the training pipeline";
  m.def("version", [] { return std::string(SOFTDECA_VERSION_STRING); });
  m.def("rig_blendshape_index", [](const std::string& name) { return softdeca::stream::rig_blendshape_index(name); },
        nb::arg("name"), "The canonical ARKit index a rig's blendshape name denotes, or -1 (docs/avatars.md).");
  m.def("tet_signed_volumes", &tet_signed_volumes, nb::arg("vertices"), nb::arg("tets"),
        "Signed tet volumes (b-a).((c-a)x(d-a))/6.");
  m.def(
      "embed_points",
      [](const Points& v, const Tets& t, const Points& p) {
        if (t.rows() > 0 && (t.minCoeff() < 0 || t.maxCoeff() >= v.rows()))
          throw nb::value_error("tets index outside the vertex array");
        auto e = embed_points(v, t, p);
        Eigen::VectorXi tet = Eigen::Map<Eigen::VectorXi>(e.tet.data(), static_cast<Eigen::Index>(e.tet.size()));
        return nb::make_tuple(tet, Eigen::MatrixXd(e.bary), Eigen::VectorXd(e.outside));
      },
      nb::arg("vertices"), nb::arg("tets"), nb::arg("points"),
      "Embed points in a tet mesh: (tet index, barycentric coordinates (n,4), distance outside).");
  m.def("cotan_laplacian", &cotan_laplacian, nb::arg("vertices"), nb::arg("triangles"),
        "Symmetric cotangent Laplacian (rows sum to zero), scipy.sparse CSC.");
  m.def("voronoi_areas", &voronoi_areas, nb::arg("vertices"), nb::arg("triangles"),
        "Mixed Voronoi vertex areas (sum to the surface area).");
  m.def("self_intersections", &self_intersections, nb::arg("vertices"), nb::arg("triangles"),
        nb::arg("max_pairs") = 1000,
        "Pairs of intersecting triangles that share no vertex (empty: no self-intersection).");
  m.def("mesh_intersections", &mesh_intersections, nb::arg("vertices_a"), nb::arg("triangles_a"),
        nb::arg("vertices_b"), nb::arg("triangles_b"), nb::arg("max_pairs") = 1000,
        "Pairs (triangle of A, triangle of B) that intersect.");
  bind_sim(m);
  bind_fit(m);
  bind_prepare(m);
  bind_rest_physics(m);
}
