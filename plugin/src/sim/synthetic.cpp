#include "sim/synthetic.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <map>
#include <cmath>

#include "core/error.h"
#include "geometry/tet_mesh.h"

namespace softdeca::sim {

void icosphere(int levels, Positions& vertices, TriIndices& triangles) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int32_t, 3>> tri = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                             {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                             {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                             {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& q : p) q.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int32_t, int32_t>, int32_t> mid;
    auto midpoint = [&](int32_t a, int32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back((p[static_cast<std::size_t>(a)] + p[static_cast<std::size_t>(b)]).normalized());
      return mid[key] = static_cast<int32_t>(p.size()) - 1;
    };
    std::vector<std::array<int32_t, 3>> next;
    next.reserve(tri.size() * 4);
    for (const auto& x : tri) {
      const int32_t a = midpoint(x[0], x[1]), b = midpoint(x[1], x[2]), c = midpoint(x[2], x[0]);
      next.push_back({x[0], a, c});
      next.push_back({x[1], b, a});
      next.push_back({x[2], c, b});
      next.push_back({a, b, c});
    }
    tri.swap(next);
  }
  vertices.resize(static_cast<Eigen::Index>(p.size()), 3);
  for (std::size_t i = 0; i < p.size(); ++i) vertices.row(static_cast<Eigen::Index>(i)) = p[i].transpose();
  triangles.resize(static_cast<Eigen::Index>(tri.size()), 3);
  for (std::size_t i = 0; i < tri.size(); ++i)
    for (int k = 0; k < 3; ++k) triangles(static_cast<Eigen::Index>(i), k) = tri[i][static_cast<std::size_t>(k)];
}

TetIndices split_prisms(const Positions& x, const TriIndices& outer, int32_t inner_offset) {
  // Sorting each face's vertices by global index makes the diagonal of every quad face run
  // from its lower-index outer vertex to its higher-index inner vertex, in both prisms that
  // share it: the tets conform.
  TetIndices tets(3 * outer.rows(), 4);
  for (Eigen::Index f = 0; f < outer.rows(); ++f) {
    std::array<int32_t, 3> p = {outer(f, 0), outer(f, 1), outer(f, 2)};
    std::sort(p.begin(), p.end());
    const std::array<int32_t, 3> q = {p[0] + inner_offset, p[1] + inner_offset, p[2] + inner_offset};
    const std::array<std::array<int32_t, 4>, 3> split = {{{p[0], p[1], p[2], q[2]}, {p[0], p[1], q[1], q[2]},
                                                          {p[0], q[0], q[1], q[2]}}};
    for (int k = 0; k < 3; ++k) {
      auto t = split[static_cast<std::size_t>(k)];
      const Eigen::Vector3d a = x.row(t[0]), b = x.row(t[1]), c = x.row(t[2]), d = x.row(t[3]);
      if ((b - a).dot((c - a).cross(d - a)) < 0) std::swap(t[2], t[3]);
      for (int j = 0; j < 4; ++j) tets(3 * f + k, j) = t[static_cast<std::size_t>(j)];
    }
  }
  return tets;
}

SimulationMesh synthetic_layered_head(const SyntheticHeadOptions& o) {
  require(o.subdivisions >= 1 && o.subdivisions <= 7, "subdivisions must be in [1, 7]");
  require(o.skin_subdivisions >= 0 && o.skin_subdivisions <= 8, "skin_subdivisions must be in [0, 8]");
  require(o.skin_radius > o.muscle_radius && o.muscle_radius > o.skull_wrap_radius &&
              o.skull_wrap_radius > o.skull_radius && o.skull_radius > 0,
          "radii must decrease from skin to skull");
  Positions unit;
  TriIndices faces;
  icosphere(o.subdivisions, unit, faces);
  const auto nv = static_cast<int32_t>(unit.rows());
  SimulationMesh m;
  // Vertex blocks: skin wrap, muscle wrap, skull wrap, skull.
  m.rest.resize(4 * nv, 3);
  const double radii[4] = {o.skin_radius, o.muscle_radius, o.skull_wrap_radius, o.skull_radius};
  for (int layer = 0; layer < 4; ++layer) m.rest.middleRows(layer * nv, nv) = radii[layer] * unit;
  m.soft_tets = split_prisms(m.rest, faces, nv);
  TriIndices muscle_outer = faces.array() + nv;
  m.muscle_tets = split_prisms(m.rest, muscle_outer, nv);
  m.skull_triangles = faces.array() + 3 * nv;

  // Connecting tets: each skull vertex with three close skull-wrap vertices: the wrap vertex
  // above it and the other two corners of its nearest wrap face (three mutually adjacent
  // vertices, so the tet is never flat).
  m.connecting_tets.resize(nv, 4);
  std::vector<double> best(static_cast<std::size_t>(nv), INFINITY);
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int32_t v = faces(f, k), a = faces(f, (k + 1) % 3), b = faces(f, (k + 2) % 3);
      const Eigen::RowVector3d s = m.rest.row(3 * nv + v);
      const double d = (m.rest.row(2 * nv + a) - s).norm() + (m.rest.row(2 * nv + b) - s).norm();
      if (d < best[static_cast<std::size_t>(v)]) {
        best[static_cast<std::size_t>(v)] = d;
        m.connecting_tets.row(v) << 3 * nv + v, 2 * nv + v, 2 * nv + a, 2 * nv + b;
      }
    }

  for (int32_t v = 0; v < nv; ++v)
    (unit(v, 1) < o.jaw_below ? m.jaw : m.cranium).vertices.push_back(3 * nv + v);
  m.cranium.pinned = m.jaw.pinned = o.pin_bones;

  // S: a finer sphere inside the soft layer, embedded in the soft tets.
  Positions s_unit;
  icosphere(o.skin_subdivisions, s_unit, m.skin_triangles);
  const double rs = o.skin_radius - o.skin_depth * (o.skin_radius - o.muscle_radius);
  const geometry::Embedding emb = geometry::embed_points(m.rest, m.soft_tets, rs * s_unit);
  require(emb.outside.maxCoeff() < 1e-9, "the synthetic skin does not lie inside the soft tissue layer");
  m.skin = embedded_points_from_tets(m.soft_tets, emb.tet, emb.bary);

  if (o.landmark_stride > 0) {
    const Eigen::Index nl = (m.skin_triangles.rows() + o.landmark_stride - 1) / o.landmark_stride;
    m.landmark_points.resize(nl, 3);
    m.landmark_weights.setConstant(nl, 3, 1.0 / 3.0);
    for (Eigen::Index l = 0; l < nl; ++l) m.landmark_points.row(l) = m.skin_triangles.row(l * o.landmark_stride);
  }
  return m;
}

}  // namespace softdeca::sim
