#include "sim/mesh.h"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "core/error.h"
#include "geometry/cotan.h"

namespace softdeca::sim {
namespace {

std::string at(const char* what, Eigen::Index i) {
  return std::string(what) + "[" + std::to_string(i) + "]";
}

template <class Indices>
void check_indices(const Indices& idx, Eigen::Index bound, const char* what, const char* bound_name) {
  for (Eigen::Index r = 0; r < idx.rows(); ++r)
    for (Eigen::Index c = 0; c < idx.cols(); ++c)
      require(idx(r, c) >= 0 && idx(r, c) < bound,
              at(what, r) + " refers to index " + std::to_string(idx(r, c)) + ", but " +
                  bound_name + " is " + std::to_string(bound));
}

double tet_volume(const Positions& x, const TetIndices& t, Eigen::Index i) {
  const Eigen::Vector3d a = x.row(t(i, 0)), b = x.row(t(i, 1)), c = x.row(t(i, 2)), d = x.row(t(i, 3));
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

void check_tets(const Positions& x, const TetIndices& t, const char* what, bool allow_negative,
                double min_volume) {
  check_indices(t, x.rows(), what, "vertex_count");
  for (Eigen::Index i = 0; i < t.rows(); ++i) {
    const double v = tet_volume(x, t, i);
    require(std::abs(v) > min_volume,
            at(what, i) + " is degenerate (volume " + std::to_string(v) + " m^3)");
    require(allow_negative || v > 0,
            at(what, i) + " is inverted (volume " + std::to_string(v) +
                " m^3): soft and muscle tets must be positively oriented");
  }
}

void check_weights(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>& w,
                   const char* what) {
  for (Eigen::Index i = 0; i < w.rows(); ++i) {
    require(w.row(i).allFinite(), at(what, i) + " has a non-finite weight", SOFTDECA_ERROR_NON_FINITE);
    require(std::abs(w.row(i).sum() - 1.0) < 1e-6,
            at(what, i) + " weights sum to " + std::to_string(w.row(i).sum()) + ", not 1");
  }
}
}  // namespace

void validate(const SimulationMesh& m) {
  const Eigen::Index n = m.vertex_count();
  require(n >= 4, "the simulation mesh needs at least 4 vertices");
  require(m.rest.allFinite(), "rest positions are not finite", SOFTDECA_ERROR_NON_FINITE);
  const double diag = (m.rest.colwise().maxCoeff() - m.rest.colwise().minCoeff()).norm();
  require(diag > 0, "rest positions all coincide");
  const double min_volume = 1e-15 * diag * diag * diag;
  check_tets(m.rest, m.soft_tets, "soft_tets", false, min_volume);
  check_tets(m.rest, m.muscle_tets, "muscle_tets", false, min_volume);
  check_tets(m.rest, m.connecting_tets, "connecting_tets", true, min_volume);
  check_indices(m.skull_triangles, n, "skull_triangles", "vertex_count");
  for (Eigen::Index i = 0; i < m.skull_triangles.rows(); ++i) {
    const Eigen::Vector3d a = m.rest.row(m.skull_triangles(i, 0)), b = m.rest.row(m.skull_triangles(i, 1)),
                          c = m.rest.row(m.skull_triangles(i, 2));
    require((b - a).cross(c - a).norm() > 1e-12 * diag * diag, at("skull_triangles", i) + " is degenerate");
  }

  std::vector<char> used(static_cast<std::size_t>(n), 0), in_bone(static_cast<std::size_t>(n), 0);
  auto mark = [&](const auto& idx) {
    for (Eigen::Index r = 0; r < idx.rows(); ++r)
      for (Eigen::Index c = 0; c < idx.cols(); ++c) used[static_cast<std::size_t>(idx(r, c))] = 1;
  };
  mark(m.soft_tets);
  mark(m.muscle_tets);
  mark(m.connecting_tets);
  mark(m.skull_triangles);
  for (const Bone* bone : {&m.cranium, &m.jaw}) {
    const char* name = bone == &m.cranium ? "cranium" : "jaw";
    for (std::size_t k = 0; k < bone->vertices.size(); ++k) {
      const int32_t v = bone->vertices[k];
      require(v >= 0 && v < n, std::string(name) + ".vertices[" + std::to_string(k) + "] = " +
                                   std::to_string(v) + " is not a vertex index");
      require(!in_bone[static_cast<std::size_t>(v)],
              "vertex " + std::to_string(v) + " is listed twice in the bones (cranium and jaw must be disjoint)");
      in_bone[static_cast<std::size_t>(v)] = 1;
      used[static_cast<std::size_t>(v)] = 1;
    }
    require(bone->pivot.allFinite() || bone->pivot.array().isNaN().all(),
            std::string(name) + ".pivot must be finite (or NaN for the centroid)");
  }

  const Eigen::Index ns = m.skin_count();
  require(m.skin.weight.rows() == ns, "skin.vertex and skin.weight have different row counts");
  check_indices(m.skin.vertex, n, "skin.vertex", "vertex_count");
  check_weights(m.skin.weight, "skin.weight");
  for (Eigen::Index i = 0; i < ns; ++i)
    for (int k = 0; k < 4; ++k)
      if (m.skin.weight(i, k) != 0) used[static_cast<std::size_t>(m.skin.vertex(i, k))] = 1;
  check_indices(m.skin_triangles, ns, "skin_triangles", "skin_count");
  if (m.skin_point_area.size()) {
    require(m.skin_point_area.size() == ns, "skin_point_area must have one entry per skin point");
    require(m.skin_point_area.allFinite() && (m.skin_point_area.array() > 0).all(),
            "skin_point_area must be positive and finite");
  } else {
    require(ns == 0 || m.skin_triangles.rows() > 0,
            "skin points need skin_triangles or skin_point_area (the area each target stands for)");
  }

  const Eigen::Index nl = m.landmark_count();
  require(m.landmark_weights.rows() == nl, "landmark_points and landmark_weights have different row counts");
  check_indices(m.landmark_points, ns, "landmark_points", "skin_count");
  check_weights(m.landmark_weights, "landmark_weights");

  for (std::size_t c = 0; c < m.collisions.size(); ++c) {
    const auto& set = m.collisions[c];
    const std::string name = "collisions[" + std::to_string(c) + "] (" + set.name + ")";
    for (int32_t p : set.points)
      require(p >= 0 && p < ns, name + ": point " + std::to_string(p) + " is not a skin point index");
    check_indices(set.surface, set.surface_on_skin ? ns : n, "collision surface",
                  set.surface_on_skin ? "skin_count" : "vertex_count");
    require(std::isfinite(set.max_distance) && set.max_distance > 0, name + ": max_distance must be positive");
  }

  for (Eigen::Index v = 0; v < n; ++v)
    require(used[static_cast<std::size_t>(v)],
            "vertex " + std::to_string(v) + " belongs to no tet, skull triangle, bone or skin point");
}

Positions embed(const EmbeddedPoints& p, const Positions& x) {
  Positions out = Positions::Zero(p.size(), 3);
  for (Eigen::Index i = 0; i < p.size(); ++i)
    for (int k = 0; k < 4; ++k)
      if (p.weight(i, k) != 0) out.row(i) += p.weight(i, k) * x.row(p.vertex(i, k));
  return out;
}

SparseRow landmark_row(const SimulationMesh& m, Eigen::Index l) {
  SparseRow row;
  for (int j = 0; j < 3; ++j) {
    const int32_t s = m.landmark_points(l, j);
    for (int k = 0; k < 4; ++k) {
      const double w = m.landmark_weights(l, j) * m.skin.weight(s, k);
      if (w == 0) continue;
      const int32_t v = m.skin.vertex(s, k);
      bool merged = false;
      for (std::size_t e = 0; e < row.vertex.size(); ++e)
        if (row.vertex[e] == v) {
          row.weight[e] += w;
          merged = true;
        }
      if (!merged) {
        row.vertex.push_back(v);
        row.weight.push_back(w);
      }
    }
  }
  return row;
}

EmbeddedPoints embedded_points_from_tets(const TetIndices& tets, const std::vector<int32_t>& tet_of_point,
                                         const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>& bary) {
  require(static_cast<Eigen::Index>(tet_of_point.size()) == bary.rows(),
          "tet_of_point and barycentric have different lengths");
  EmbeddedPoints p;
  p.vertex.resize(bary.rows(), 4);
  p.weight = bary;
  for (Eigen::Index i = 0; i < bary.rows(); ++i) {
    const int32_t t = tet_of_point[static_cast<std::size_t>(i)];
    require(t >= 0 && t < tets.rows(), at("tet_of_point", i) + " is not a tet index");
    p.vertex.row(i) = tets.row(t);
  }
  return p;
}

Eigen::VectorXd skin_point_areas(const SimulationMesh& m) {
  if (m.skin_point_area.size()) return m.skin_point_area;
  const Positions s = embed(m.skin, m.rest);
  Eigen::VectorXd a = geometry::voronoi_areas(s, m.skin_triangles);
  // Points on no triangle would get no weight: give them the mean area instead.
  const double mean = a.size() ? a.sum() / static_cast<double>(a.size()) : 0.0;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (!(a[i] > 0)) a[i] = mean > 0 ? mean : 1e-6;
  return a;
}

}  // namespace softdeca::sim
