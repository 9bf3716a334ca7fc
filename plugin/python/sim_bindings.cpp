// Python bindings of the physics simulator phi† (plugin/src/sim): build a simulation mesh from
// numpy arrays, set parameters globally or per element, solve static frames, batches and
// dynamic sequences, read positions and statistics. Solves release the GIL.
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "sim/collisions.h"
#include "sim/simulator.h"
#include "sim/synthetic.h"

namespace nb = nanobind;
using namespace softdeca::sim;

namespace {
using Mat4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
using Idx4 = Eigen::Matrix<int32_t, Eigen::Dynamic, 4, Eigen::RowMajor>;
using Idx3 = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
using W4 = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;
using W3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Stack = nb::ndarray<const double, nb::shape<-1, -1, 3>, nb::c_contig, nb::device::cpu>;
using StackOut = nb::ndarray<nb::numpy, double, nb::shape<-1, -1, 3>>;
using Transforms = nb::ndarray<const double, nb::shape<-1, 4, 4>, nb::c_contig, nb::device::cpu>;

nb::dict stats_dict(const SolveStats& s) {
  nb::dict d;
  d["iterations"] = s.iterations;
  d["converged"] = s.converged;
  d["relative_step"] = s.relative_step;
  d["estimated_error"] = s.estimated_error;
  d["contraction"] = s.contraction;
  d["energy"] = s.energy;
  d["energy_history"] = s.energy_history;
  d["anderson_rejections"] = s.anderson_rejections;
  d["target_rms"] = s.target_rms;
  d["max_target_distance"] = s.max_target_distance;
  d["inverted_elements"] = s.inverted_elements;
  d["inversion_rounds"] = s.inversion_rounds;
  d["stiffened_elements"] = s.stiffened_elements;
  d["local_seconds"] = s.local_seconds;
  d["global_seconds"] = s.global_seconds;
  d["factor_seconds"] = s.factor_seconds;
  d["total_seconds"] = s.total_seconds;
  d["penetrating_before"] = s.penetrating_before;
  d["penetrating_after"] = s.penetrating_after;
  d["contacts"] = s.contacts;
  d["collision_rounds"] = s.collision_rounds;
  d["max_contact_gap"] = s.max_contact_gap;
  d["max_contact_correction"] = s.max_contact_correction;
  d["rejected_collision_rounds"] = s.rejected_collision_rounds;
  d["collision_seconds"] = s.collision_seconds;
  return d;
}

Eigen::Isometry3d isometry(const std::optional<Mat4>& m) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (m) T.matrix() = *m;
  return T;
}

Positions frame_of(const Stack& a, std::size_t f) {
  const std::size_t n = a.shape(1);
  Positions p(static_cast<Eigen::Index>(n), 3);
  std::copy(a.data() + f * n * 3, a.data() + (f + 1) * n * 3, p.data());
  return p;
}

StackOut stack(const std::vector<FrameResult>& r, bool skin) {
  const std::size_t frames = r.size();
  const std::size_t n = frames ? static_cast<std::size_t>((skin ? r[0].skin : r[0].vertices).rows()) : 0;
  auto* data = new double[frames * n * 3];
  for (std::size_t f = 0; f < frames; ++f) {
    const Positions& p = skin ? r[f].skin : r[f].vertices;
    std::copy(p.data(), p.data() + n * 3, data + f * n * 3);
  }
  nb::capsule owner(data, [](void* p) noexcept { delete[] static_cast<double*>(p); });
  return StackOut(data, {frames, n, 3}, owner);
}

std::vector<FrameInput> frames_of(const Stack& skin, const std::optional<Stack>& landmarks,
                                  const std::optional<Transforms>& jaw) {
  std::vector<FrameInput> in(skin.shape(0));
  if (landmarks && landmarks->shape(0) != skin.shape(0))
    throw nb::value_error("landmark_targets must have as many frames as skin_targets");
  if (jaw && jaw->shape(0) != skin.shape(0)) throw nb::value_error("jaw must have as many frames as skin_targets");
  for (std::size_t f = 0; f < in.size(); ++f) {
    in[f].skin_targets = frame_of(skin, f);
    if (landmarks) in[f].landmark_targets = frame_of(*landmarks, f);
    if (jaw) in[f].bones.jaw = isometry(Mat4(Eigen::Map<const Mat4>(jaw->data() + 16 * f)));
  }
  return in;
}

nb::tuple results(const std::vector<FrameResult>& r) {
  nb::list stats;
  for (const auto& x : r) stats.append(stats_dict(x.stats));
  return nb::make_tuple(stack(r, true), stack(r, false), stats);
}

FrameInput frame_input(const Positions& skin, const std::optional<Positions>& landmarks, const std::optional<Mat4>& cranium,
                       const std::optional<Mat4>& jaw, const std::optional<Positions>& warm_start) {
  FrameInput in;
  in.skin_targets = skin;
  if (landmarks) in.landmark_targets = *landmarks;
  in.bones.cranium = isometry(cranium);
  in.bones.jaw = isometry(jaw);
  if (warm_start) in.warm_start = *warm_start;
  return in;
}

nb::tuple single(const FrameResult& r) { return nb::make_tuple(r.vertices, r.skin, stats_dict(r.stats)); }

// One frame through a Simulator member (static or dynamic) with the GIL released.
template <FrameResult (Simulator::*solve)(const FrameInput&)>
nb::tuple solve_one(Simulator& s, const Positions& skin, std::optional<Positions> landmarks, std::optional<Mat4> cranium,
                    std::optional<Mat4> jaw, std::optional<Positions> warm_start) {
  const FrameInput in = frame_input(skin, landmarks, cranium, jaw, warm_start);
  FrameResult r;
  {
    nb::gil_scoped_release release;
    r = (s.*solve)(in);
  }
  return single(r);
}

// A stack of frames through a Simulator member (batch or sequence) with the GIL released.
template <std::vector<FrameResult> (Simulator::*solve)(const std::vector<FrameInput>&)>
nb::tuple solve_many(Simulator& s, const Stack& skin, std::optional<Stack> landmarks, std::optional<Transforms> jaw) {
  const std::vector<FrameInput> in = frames_of(skin, landmarks, jaw);
  std::vector<FrameResult> r;
  {
    nb::gil_scoped_release release;
    r = (s.*solve)(in);
  }
  return results(r);
}

void register_error_translator() {
  // softdeca::Error (bad input) surfaces as ValueError with the library's message.
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const softdeca::Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
}

void bind_parameters(nb::module_& m) {

  m.def("parameter_table", [] {
    nb::list out;
    const auto& table = parameter_table();
    for (std::size_t i = 0; i < table.size(); ++i) {
      const softdeca::ParameterSpec& p = table[i];
      nb::dict d;  // keyed as parameters.json's entries
      d["name"] = p.name;
      d["symbol"] = p.symbol;
      d["default"] = p.default_value;
      d["lo"] = p.minimum;
      d["hi"] = p.maximum;
      d["scale"] = p.log_scale ? "log" : "linear";
      d["unit"] = p.unit;
      d["domain"] = p.domain;
      d["refactor"] = parameter_refactors(static_cast<Param>(i));
      d["description"] = p.description;
      out.append(d);
    }
    return out;
  }, "The material parameters p as compiled in from plugin/data/parameters.json, keyed as its entries.");
  m.def("parameters_json", [] { return std::string(parameters_json()); },
        "plugin/data/parameters.json verbatim, as compiled in.");
}

void bind_collision_set(nb::module_& m) {
  nb::class_<CollisionSet>(m, "CollisionSet",
                           "Skin points that must stay on the outer side of an oriented surface (lips, teeth).")
      .def(
          "__init__",
          [](CollisionSet* s, std::string name, std::vector<int32_t> points, Idx3 surface, bool surface_on_skin,
             double max_distance) {
            new (s) CollisionSet{std::move(name), std::move(points), std::move(surface), surface_on_skin, max_distance};
          },
          nb::arg("name"), nb::arg("points"), nb::arg("surface"), nb::arg("surface_on_skin") = true,
          nb::arg("max_distance") = 0.01)
      .def_ro("name", &CollisionSet::name)
      .def_ro("points", &CollisionSet::points)
      .def_ro("surface", &CollisionSet::surface);
}

void bind_simulation_mesh(nb::module_& m) {
  nb::class_<SimulationMesh>(m, "SimulationMesh",
                             "The simulation mesh: simulated vertices, tet groups, skull, bones, embedded skin S.")
      .def(
          "__init__",
          [](SimulationMesh* mesh, Positions rest, Idx4 soft_tets, Idx4 muscle_tets, Idx4 connecting_tets,
             Idx3 skull_triangles, std::vector<int32_t> cranium_vertices, std::vector<int32_t> jaw_vertices,
             bool cranium_pinned, bool jaw_pinned, std::optional<Eigen::Vector3d> cranium_pivot,
             std::optional<Eigen::Vector3d> jaw_pivot, Idx4 skin_vertices, W4 skin_weights, Idx3 skin_triangles,
             std::optional<Eigen::VectorXd> skin_point_area, std::optional<Idx3> landmark_points,
             std::optional<W3> landmark_weights, std::vector<CollisionSet> collisions) {
            SimulationMesh* m = new (mesh) SimulationMesh();
            m->rest = std::move(rest);
            m->soft_tets = std::move(soft_tets);
            m->muscle_tets = std::move(muscle_tets);
            m->connecting_tets = std::move(connecting_tets);
            m->skull_triangles = std::move(skull_triangles);
            m->cranium.vertices = std::move(cranium_vertices);
            m->jaw.vertices = std::move(jaw_vertices);
            m->cranium.pinned = cranium_pinned;
            m->jaw.pinned = jaw_pinned;
            if (cranium_pivot) m->cranium.pivot = *cranium_pivot;
            if (jaw_pivot) m->jaw.pivot = *jaw_pivot;
            m->skin.vertex = std::move(skin_vertices);
            m->skin.weight = std::move(skin_weights);
            m->skin_triangles = std::move(skin_triangles);
            if (skin_point_area) m->skin_point_area = *skin_point_area;
            if (landmark_points) m->landmark_points = *landmark_points;
            else m->landmark_points.resize(0, 3);
            if (landmark_weights) m->landmark_weights = *landmark_weights;
            else m->landmark_weights.resize(0, 3);
            m->collisions = std::move(collisions);
            validate(*m);
          },
          nb::arg("rest"), nb::arg("soft_tets"), nb::arg("muscle_tets"), nb::arg("connecting_tets"),
          nb::arg("skull_triangles"), nb::arg("cranium_vertices"), nb::arg("jaw_vertices"),
          nb::arg("cranium_pinned") = true, nb::arg("jaw_pinned") = true, nb::arg("cranium_pivot") = nb::none(),
          nb::arg("jaw_pivot") = nb::none(), nb::arg("skin_vertices"), nb::arg("skin_weights"),
          nb::arg("skin_triangles"), nb::arg("skin_point_area") = nb::none(), nb::arg("landmark_points") = nb::none(),
          nb::arg("landmark_weights") = nb::none(), nb::arg("collisions") = std::vector<CollisionSet>{},
          "Validates and stores the mesh (ValueError with the first problem). skin_vertices/skin_weights: "
          "(n, 4) simulated vertices and barycentric weights per skin point (see skin_embedding_from_tets).")
      .def_prop_ro("rest", [](const SimulationMesh& m) { return m.rest; })
      .def_prop_ro("soft_tets", [](const SimulationMesh& m) { return m.soft_tets; })
      .def_prop_ro("muscle_tets", [](const SimulationMesh& m) { return m.muscle_tets; })
      .def_prop_ro("connecting_tets", [](const SimulationMesh& m) { return m.connecting_tets; })
      .def_prop_ro("skull_triangles", [](const SimulationMesh& m) { return m.skull_triangles; })
      .def_prop_ro("skin_vertices", [](const SimulationMesh& m) { return m.skin.vertex; })
      .def_prop_ro("skin_weights", [](const SimulationMesh& m) { return m.skin.weight; })
      .def_prop_ro("skin_triangles", [](const SimulationMesh& m) { return m.skin_triangles; })
      .def_prop_ro("cranium_vertices", [](const SimulationMesh& m) { return m.cranium.vertices; })
      .def_prop_ro("jaw_vertices", [](const SimulationMesh& m) { return m.jaw.vertices; })
      .def_prop_ro("landmark_points", [](const SimulationMesh& m) { return m.landmark_points; })
      .def_prop_ro("landmark_weights", [](const SimulationMesh& m) { return m.landmark_weights; })
      .def_prop_ro("vertex_count", &SimulationMesh::vertex_count)
      .def_prop_ro("skin_count", &SimulationMesh::skin_count)
      .def_prop_ro("landmark_count", &SimulationMesh::landmark_count)
      .def("embed_skin", [](const SimulationMesh& m, const Positions& x) { return embed(m.skin, x); }, nb::arg("vertices"),
           "Skin point positions for simulated vertex positions.");
}

void bind_mesh_functions(nb::module_& m) {
  m.def(
      "find_penetrations",
      [](const SimulationMesh& mesh, const Positions& skin, const Positions& vertices, double tolerance) {
        if (skin.rows() != mesh.skin_count() || vertices.rows() != mesh.vertex_count())
          throw nb::value_error("skin and vertices must match the mesh's skin and vertex counts");
        nb::list out;
        for (const Contact& c : find_penetrations(mesh, skin, vertices, tolerance))
          out.append(nb::make_tuple(mesh.collisions[static_cast<std::size_t>(c.set)].name, c.point, c.depth));
        return out;
      },
      nb::arg("mesh"), nb::arg("skin"), nb::arg("vertices"), nb::arg("tolerance") = 1e-5,
      "Skin points behind their collision surface: [(set name, skin point, depth in m)].");
  m.def(
      "skin_embedding_from_tets",
      [](const Idx4& tets, const std::vector<int32_t>& tet_index, const W4& bary) {
        const EmbeddedPoints e = embedded_points_from_tets(tets, tet_index, bary);
        return nb::make_tuple(e.vertex, e.weight);
      },
      nb::arg("tets"), nb::arg("tet_index"), nb::arg("barycentric"),
      "(tet, barycentric) per point (as from embed_points) -> (vertices (n, 4), weights (n, 4)).");

  m.def(
      "synthetic_layered_head",
      [](int subdivisions, int skin_subdivisions, bool pin_bones, int landmark_stride) {
        SyntheticHeadOptions o;
        o.subdivisions = subdivisions;
        o.skin_subdivisions = skin_subdivisions;
        o.pin_bones = pin_bones;
        o.landmark_stride = landmark_stride;
        return synthetic_layered_head(o);
      },
      nb::arg("subdivisions") = 2, nb::arg("skin_subdivisions") = 3, nb::arg("pin_bones") = true,
      nb::arg("landmark_stride") = 0,
      "A synthetic layered head: concentric icosphere wraps (radii 10, 8.5, 7.5 cm), prism tets, a skull sphere "
      "(7 cm) split into cranium and jaw, S a finer sphere embedded in the soft layer.");
}

void bind_simulator(nb::module_& m) {
  nb::class_<Simulator>(m, "Simulator", "phi†: the projective-dynamics simulator of one layered head.")
      .def(
          "__init__",
          [](Simulator* s, const SimulationMesh& mesh, int max_iterations, double tolerance, int anderson_window,
             int threads, bool paper_strain_rule, int collision_rounds, double collision_weight,
             double penetration_tolerance, bool lips_follow_targets, int inversion_rounds) {
            SolverSettings st;
            st.max_iterations = max_iterations;
            st.tolerance = tolerance;
            st.anderson_window = anderson_window;
            st.threads = threads;
            st.strain_limit = paper_strain_rule ? StrainLimit::kPaperRotation : StrainLimit::kNearestInSet;
            st.collision_rounds = collision_rounds;
            st.collision_weight = collision_weight;
            st.penetration_tolerance = penetration_tolerance;
            st.lips_follow_targets = lips_follow_targets;
            st.inversion_rounds = inversion_rounds;
            new (s) Simulator(mesh, st);
          },
          nb::arg("mesh"), nb::arg("max_iterations") = SolverSettings{}.max_iterations,
          nb::arg("tolerance") = SolverSettings{}.tolerance, nb::arg("anderson_window") = SolverSettings{}.anderson_window,
          nb::arg("threads") = 0, nb::arg("paper_strain_rule") = false,
          nb::arg("collision_rounds") = SolverSettings{}.collision_rounds,
          nb::arg("collision_weight") = SolverSettings{}.collision_weight,
          nb::arg("penetration_tolerance") = SolverSettings{}.penetration_tolerance,
          nb::arg("lips_follow_targets") = SolverSettings{}.lips_follow_targets,
          nb::arg("inversion_rounds") = SolverSettings{}.inversion_rounds)
      .def("set_parameter", [](Simulator& s, const std::string& name, double v) { s.parameters().set(name, v); },
           nb::arg("name"), nb::arg("value"), "Sets a parameter everywhere (ValueError when out of range).")
      .def("get_parameter", [](const Simulator& s, const std::string& name) {
             return s.parameters().global(find_parameter(name));
           }, nb::arg("name"))
      .def("set_parameter_field",
           [](Simulator& s, const std::string& name, const Eigen::VectorXd& v) { s.parameters().set_field(name, v); },
           nb::arg("name"), nb::arg("values"), "Per-element values over the parameter's domain.")
      .def("parameters", [](const Simulator& s) {
             nb::dict d;
             for (std::size_t i = 0; i < parameter_table().size(); ++i)
               d[parameter_table()[i].name.c_str()] = s.parameters().global(static_cast<Param>(i));
             return d;
           }, "Global values of all parameters.")
      .def(
          "solve_static", &solve_one<&Simulator::solve_static>,
          nb::arg("skin_targets"), nb::arg("landmark_targets") = nb::none(), nb::arg("cranium") = nb::none(),
          nb::arg("jaw") = nb::none(), nb::arg("warm_start") = nb::none(),
          "One static frame -> (vertices, skin, stats). cranium/jaw: 4x4 rigid transforms of pinned bones.")
      .def(
          "step_dynamic", &solve_one<&Simulator::step_dynamic>,
          nb::arg("skin_targets"), nb::arg("landmark_targets") = nb::none(), nb::arg("cranium") = nb::none(),
          nb::arg("jaw") = nb::none(), nb::arg("warm_start") = nb::none(),
          "The next dynamic frame (eq. 9) -> (vertices, skin, stats).")
      .def("reset_dynamics", &Simulator::reset_dynamics)
      .def("dynamic_target", &Simulator::dynamic_skin_target, nb::arg("skin_targets"),
           "The blended target (eq. 9) the next step_dynamic solves toward for these skin targets "
           "(the targets themselves before the first frame); changes nothing.")
      .def(
          "solve_static_batch", &solve_many<&Simulator::solve_static_batch>,
          nb::arg("skin_targets"), nb::arg("landmark_targets") = nb::none(), nb::arg("jaw") = nb::none(),
          "Static frames (F, n, 3) (jaw: (F, 4, 4) rigid transforms) over one factorisation on all threads -> "
          "(skin (F, n, 3), vertices (F, N, 3), stats list).")
      .def(
          "solve_sequence", &solve_many<&Simulator::solve_sequence>,
          nb::arg("skin_targets"), nb::arg("landmark_targets") = nb::none(), nb::arg("jaw") = nb::none(),
          "A dynamic sequence from rest of the dynamics -> (skin, vertices, stats list).")
      .def("rest_positions", &Simulator::rest_positions)
      .def_prop_ro("length_scale", &Simulator::length_scale)
      .def_prop_ro("factorizations", &Simulator::factorizations)
      .def_prop_ro("thread_count", &Simulator::thread_count)
      .def_prop_ro("mesh", &Simulator::mesh, nb::rv_policy::reference_internal);
}
}  // namespace

void bind_sim(nb::module_& m) {
  register_error_translator();
  bind_parameters(m);
  bind_collision_set(m);
  bind_simulation_mesh(m);
  bind_mesh_functions(m);
  bind_simulator(m);
}
