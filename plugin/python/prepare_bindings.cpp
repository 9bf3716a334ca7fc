// Python bindings of prepare's rules, each implemented once in the library and shared with the
// training package: the contact rules (plugin/src/prepare/contact_sets.h), the lip and lid sets
// data generation (training/softdeca_train/sim) and the runtime's prepare find, whose arguments
// carry the names of softdeca_train.contact_rules.ContactRules' fields so that `**vars(rules)`
// passes them; the parameter localisation rules (prepare/parameters.h) that
// softdeca_train.models.parameters.ParameterState applies; and the fill's carry to a neutral
// skin (prepare/rest_physics.h) with its stiffness, which the training package's carried fills
// (lhm/carried.py, models/rest_head.py) use.
#include <nanobind/eigen/dense.h>
#include <nanobind/eigen/sparse.h>
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>
#include <vector>

#include "prepare/contact_sets.h"
#include "prepare/parameters.h"
#include "prepare/rest_physics.h"

namespace nb = nanobind;
using namespace softdeca;

namespace {
using Indices = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 1>;
using Flags = Eigen::Matrix<std::int8_t, Eigen::Dynamic, 1>;
using Line = Eigen::Matrix<double, 4, 3, Eigen::RowMajor>;
using Values = Eigen::VectorXd;

// Per-point flags (0/1 or -1/0/+1) as an int8 array.
template <class T>
Flags to_flags(const std::vector<T>& v) {
  Flags out(static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) out[static_cast<Eigen::Index>(i)] = static_cast<std::int8_t>(v[i]);
  return out;
}

std::vector<std::int32_t> to_vector(const Indices& v) { return {v.data(), v.data() + v.size()}; }
Indices to_indices(const std::vector<std::int32_t>& v) {
  return Eigen::Map<const Indices>(v.data(), static_cast<Eigen::Index>(v.size()));
}

void check_below(const Indices& v, Eigen::Index n, const char* what) {
  if (v.size() > 0 && (v.minCoeff() < 0 || v.maxCoeff() >= n))
    throw nb::value_error((std::string(what) + " name a vertex outside the skin").c_str());
}

void check_landmarks(const sim::Positions& skin, const Indices& landmarks68) {
  if (landmarks68.size() != 68) throw nb::value_error("landmarks68 must hold the 68 landmarks' skin vertices");
  check_below(landmarks68, skin.rows(), "landmarks68");
}

std::vector<std::int32_t> triangle_list(const sim::Positions& skin, const sim::TriIndices& tris) {
  if (tris.size() > 0 && (tris.minCoeff() < 0 || tris.maxCoeff() >= skin.rows()))
    throw nb::value_error("skin_triangles name a vertex outside the skin");
  return {tris.data(), tris.data() + tris.size()};
}

prepare::ContactRules rules_of(const sim::Positions& skin, const Indices& landmarks68, const Indices& lid_candidates,
                               double lip_radius, double lip_corner_radius, double lid_reach, double lid_corner_radius,
                               double eye_zone_share) {
  check_landmarks(skin, landmarks68);
  check_below(lid_candidates, skin.rows(), "lid_candidates");
  return {to_vector(landmarks68), to_vector(lid_candidates), lip_radius, lip_corner_radius,
          lid_reach,              lid_corner_radius,          eye_zone_share};
}

// The rules' keyword arguments, after the function's own; defaults from contact_rules.json.
template <class F, class... Extra>
void def_with_rules(nb::module_& m, const char* name, F&& f, const char* doc, Extra&&... own) {
  const prepare::ContactRules d;
  m.def(name, std::forward<F>(f), std::forward<Extra>(own)..., nb::kw_only(), nb::arg("landmarks68"),
        nb::arg("lid_candidates") = Indices(), nb::arg("lip_radius") = d.lip_radius,
        nb::arg("lip_corner_radius") = d.lip_corner_radius, nb::arg("lid_reach") = d.lid_reach,
        nb::arg("lid_corner_radius") = d.lid_corner_radius, nb::arg("eye_zone_share") = d.eye_zone_share, doc);
}

void bind_localisation(nb::module_& m) {
  m.def(
      "localise_to_faces",
      [](const Values& vertex_values, const sim::TriIndices& triangles) {
        if (triangles.size() > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= vertex_values.size()))
          throw nb::value_error("triangles name a vertex the vertex map has no value for");
        const std::vector<std::int32_t> t(triangles.data(), triangles.data() + triangles.size());
        Values out(triangles.rows());
        prepare::faces_from_vertex_map(t, vertex_values.data(), out.data());
        return out;
      },
      nb::arg("vertex_values"), nb::arg("triangles"), "A vertex map on the faces: the mean of each triangle's corners.");
  m.def(
      "localise_to_vertices",
      [](const Values& face_values, const sim::TriIndices& triangles, const Values& face_area, int n_vertices) {
        if (face_values.size() != triangles.rows() || face_area.size() != triangles.rows())
          throw nb::value_error("face_values and face_area need one value per triangle");
        if (triangles.size() > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= n_vertices))
          throw nb::value_error("triangles name a vertex at or past n_vertices");
        const std::vector<std::int32_t> t(triangles.data(), triangles.data() + triangles.size());
        const std::vector<double> area(face_area.data(), face_area.data() + face_area.size());
        Values out(n_vertices);
        prepare::vertices_from_face_map(t, area, prepare::skin_vertex_areas(t, area, static_cast<std::size_t>(n_vertices)),
                                        face_values.data(), out.data());
        return out;
      },
      nb::arg("face_values"), nb::arg("triangles"), nb::arg("face_area"), nb::arg("n_vertices"),
      "A face map on the vertices: the area-weighted mean of each vertex's incident faces.");
}

void check_tets(const sim::TetIndices& tets, Eigen::Index n, const char* what) {
  if (tets.size() > 0 && (tets.minCoeff() < 0 || tets.maxCoeff() >= n))
    throw nb::value_error((std::string(what) + " name a vertex outside the fill").c_str());
}

void bind_carry(nb::module_& m) {
  m.def(
      "fill_stiffness",
      [](const sim::Positions& vertices, const sim::TetIndices& tets) {
        check_tets(tets, vertices.rows(), "tets");
        std::vector<Eigen::Triplet<double>> k;
        prepare::add_fill_stiffness(vertices, tets, 1.0, k);
        Eigen::SparseMatrix<double> out(vertices.rows(), vertices.rows());
        out.setFromTriplets(k.begin(), k.end());
        return out;
      },
      nb::arg("vertices"), nb::arg("tets"),
      "(n, n) sum over tets of vol * grad(phi_a) . grad(phi_b): the Dirichlet energy of a piecewise-linear field "
      "is x^T K x per component (scipy.sparse CSC).");
  m.def(
      "carry_fill",
      [](const sim::Positions& vertices, const sim::TetIndices& soft_tets, const sim::TetIndices& muscle_tets,
         const Eigen::Matrix<std::int32_t, Eigen::Dynamic, 4, Eigen::RowMajor>& skin_vertex,
         const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>& skin_weight, const Values& carry_weight,
         double carry_smoothness, const sim::Positions& neutral_skin) {
        check_tets(soft_tets, vertices.rows(), "soft_tets");
        check_tets(muscle_tets, vertices.rows(), "muscle_tets");
        check_tets(skin_vertex, vertices.rows(), "skin_vertex");
        if (skin_weight.rows() != skin_vertex.rows() || carry_weight.size() != skin_vertex.rows())
          throw nb::value_error("skin_vertex, skin_weight and carry_weight need one row per skin point");
        prepare::RestHead head;
        head.vertices = vertices;
        head.soft_tets = soft_tets;
        head.muscle_tets = muscle_tets;
        head.skin = {skin_vertex, skin_weight};
        head.carry_weight.assign(carry_weight.data(), carry_weight.data() + carry_weight.size());
        head.carry_smoothness = carry_smoothness;
        return prepare::carry_fill(head, neutral_skin);
      },
      nb::arg("vertices"), nb::arg("soft_tets"), nb::arg("muscle_tets"), nb::arg("skin_vertex"), nb::arg("skin_weight"),
      nb::arg("carry_weight"), nb::arg("carry_smoothness"), nb::arg("neutral_skin"),
      "The fill's vertices carried to a neutral skin: V0 + K^-1 B^T W (S - B V0) (docs/bundle.md, Rest physics).");
}
}  // namespace

void bind_prepare(nb::module_& m) {
  bind_localisation(m);
  bind_carry(m);
  m.def(
      "lip_contact_zone",
      [](const sim::Positions& skin, const Indices& landmarks68, double radius) {
        check_landmarks(skin, landmarks68);
        return to_flags(prepare::lip_contact_zone(skin, to_vector(landmarks68), radius));
      },
      nb::arg("skin"), nb::arg("landmarks68"), nb::arg("radius") = prepare::ContactRules{}.lip_radius,
      "Per skin point, 1 where it lies within `radius` of the inner lip contour, else 0.");
  def_with_rules(
      m, "lip_sets",
      [](const sim::Positions& skin, const sim::TriIndices& skin_triangles, const Indices& landmarks68,
         const Indices& lid_candidates, double lr, double lcr, double ldr, double ldcr, double ezs) {
        const prepare::LipSets s = prepare::lip_sets(rules_of(skin, landmarks68, lid_candidates, lr, lcr, ldr, ldcr, ezs),
                                                     skin, triangle_list(skin, skin_triangles));
        return nb::make_tuple(to_indices(s.zone), to_indices(s.upper), to_indices(s.lower), s.upper_triangles,
                              s.lower_triangles);
      },
      "The lip sets: (zone, upper, lower, upper_triangles, lower_triangles).", nb::arg("skin"),
      nb::arg("skin_triangles"));
  m.def(
      "eye_fissures",
      [](const sim::Positions& skin, const Indices& landmarks68) {
        check_landmarks(skin, landmarks68);
        std::vector<Line> out;
        for (const prepare::FissureLine& line : prepare::eye_fissures(skin, to_vector(landmarks68))) {
          Line l;
          for (int k = 0; k < 4; ++k) l.row(k) = line[static_cast<std::size_t>(k)].transpose();
          out.push_back(l);
        }
        return out;
      },
      nb::arg("skin"), nb::arg("landmarks68"),
      "Each eye's fissure (right, then left): (4, 3) corner, lid midpoints, corner.");
  m.def(
      "lid_sides",
      [](const sim::Positions& skin, const Indices& landmarks68, double eye_zone_share) {
        check_landmarks(skin, landmarks68);
        return to_flags(prepare::lid_sides(skin, to_vector(landmarks68), eye_zone_share));
      },
      nb::arg("skin"), nb::arg("landmarks68"), nb::arg("eye_zone_share") = prepare::ContactRules{}.eye_zone_share,
      "Per skin point: +1 on an upper lid's side of its eye's fissure, -1 on a lower lid's, 0 away from the eyes.");
  def_with_rules(
      m, "lid_sets",
      [](const sim::Positions& skin, const Indices& landmarks68, const Indices& lid_candidates, double lr, double lcr,
         double ldr, double ldcr, double ezs) {
        const prepare::LidSets s =
            prepare::lid_sets(rules_of(skin, landmarks68, lid_candidates, lr, lcr, ldr, ldcr, ezs), skin);
        return nb::make_tuple(to_indices(s.upper), to_indices(s.lower));
      },
      "The lid sets: (upper, lower), skin point indices of both eyes.", nb::arg("skin"));
  def_with_rules(
      m, "contact_sets",
      [](const sim::Positions& skin, const sim::TriIndices& skin_triangles, const sim::TriIndices& upper_teeth,
         const sim::TriIndices& lower_teeth, const Indices& landmarks68, const Indices& lid_candidates, double lr,
         double lcr, double ldr, double ldcr, double ezs) {
        return prepare::contact_sets(rules_of(skin, landmarks68, lid_candidates, lr, lcr, ldr, ldcr, ezs), skin,
                                     triangle_list(skin, skin_triangles), upper_teeth, lower_teeth);
      },
      "A head's five collision sets (CollisionSet): the lips against each other and the teeth, the eyelids. "
      "upper_teeth / lower_teeth: the teeth's triangles over simulated vertices.",
      nb::arg("skin"), nb::arg("skin_triangles"), nb::arg("upper_teeth"), nb::arg("lower_teeth"));
}
