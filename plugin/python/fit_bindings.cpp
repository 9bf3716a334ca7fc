// Python bindings of the avatar fit's steps (plugin/src/fit), for the training package's tools
// and the tests that hold them on real meshes (the ICT template, ARKit's reference face).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include "core/error.h"
#include "fit/avatar_frame.h"

namespace nb = nanobind;
using namespace softdeca::fit;

namespace {
using Vertices = nb::ndarray<const float, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;
using Shapes = nb::ndarray<const float, nb::shape<52, -1, 3>, nb::c_contig, nb::device::cpu>;
using Present = nb::ndarray<const bool, nb::shape<52>, nb::c_contig, nb::device::cpu>;
using Triangles = nb::ndarray<const int32_t, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;

nb::tuple vec(const Eigen::Vector3d& v) { return nb::make_tuple(v.x(), v.y(), v.z()); }
}  // namespace

void bind_fit(nb::module_& m) {
  m.def(
      "avatar_frame",
      [](const Vertices& neutral, const Shapes& deltas, const Present& present, std::optional<Triangles> triangles) {
        if (deltas.shape(1) != neutral.shape(0)) throw nb::value_error("deltas must be (52, vertex count, 3)");
        AvatarShapes s;
        s.neutral = neutral.data();
        s.vertex_count = neutral.shape(0);
        for (std::size_t i = 0; i < kShapes; ++i)
          s.deltas[i] = present.data()[i] ? deltas.data() + i * 3 * s.vertex_count : nullptr;
        if (triangles) {
          s.triangles = triangles->data();
          s.triangle_count = triangles->shape(0);
        }
        AvatarFrame f;
        try {
          f = avatar_frame(s);
        } catch (const softdeca::Error& e) {
          throw nb::value_error(e.what());
        }
        nb::dict d;
        d["left"] = vec(f.left);
        d["up"] = vec(f.up);
        d["forward"] = vec(f.forward);
        d["eyes"] = vec(f.eyes);
        d["eye_distance"] = f.eye_distance;
        d["metres_per_unit"] = f.metres_per_unit;
        d["metres_per_unit_measured"] = f.metres_per_unit_measured;
        d["up_axis"] = f.up_axis;
        d["mirrored"] = f.mirrored;
        d["face_vertices"] = f.face_vertices;
        d["shapes_used"] = f.shapes_used;
        nb::list face;
        for (std::size_t v = 0; v < f.face.size(); ++v)
          if (f.face[v]) face.append(v);
        d["face"] = face;
        return d;
      },
      nb::arg("neutral"), nb::arg("deltas"), nb::arg("present"), nb::arg("triangles") = nb::none(),
      "Where an avatar's face is, its left, up and forward directions and its unit, from its ARKit shapes "
      "(neutral (n, 3) float32, deltas (52, n, 3) float32 in canonical order, present (52,) bool).");
}
