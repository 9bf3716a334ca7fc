// Where each template vertex lands on an avatar. Closest points alone slide along the skin; what
// pins a point of a face is how it moves: a vertex's response to the ARKit shapes (each shape's
// motion over that shape's largest, so a rig's amplitudes and units cancel) is a descriptor any
// ARKit rig shares with the template. A template vertex the shapes move clearly is matched to
// the point of the avatar's skin with the most alike response near it (the best vertex, then
// the best point of the triangles around it); the others, and every vertex in the last
// iterations' fine fit, take their closest point.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "fit/registration.h"
#include "geometry/surface_query.h"

namespace softdeca::fit {

// One ARKit shape both meshes have: its deltas on the avatar (its own coordinates, read where
// they are: a large avatar's shapes are not copied) and on the template (its frame, metres).
struct SharedShape {
  const float* avatar = nullptr;  // per avatar vertex, xyz
  Points template_;               // per template skin vertex
};

class ShapeMatcher {
 public:
  // `triangles`: the avatar's skin triangles over its `vertices`, with their open edges (bit k:
  // the edge opposite corner k) and open vertices; `data_weight`: per template skin vertex.
  // What depends on the avatar alone (its responses, in its own axes) is read once; place()
  // then puts it where the template is, before any search.
  ShapeMatcher(const Triangles& triangles, std::size_t vertices, std::vector<uint8_t> boundary_edges,
               std::vector<uint8_t> boundary_vertex, std::vector<double> data_weight, const std::vector<SharedShape>& shapes);

  // The avatar placed: `avatar`, its vertices in the template's frame, by a placement whose
  // linear part `to_template` is a similarity (a rotation or reflection, and a scale);
  // `cutting`: the surface query's long triangles cut into pieces (geometry/surface_query.h), at
  // the first placement; a later one (a small rigid correction) moves the same pieces.
  void place(const Points& avatar, const Eigen::Matrix3d& to_template, const geometry::Cutting& cutting);

  void operator()(const Points& skin, const Points& normals, double reach, std::vector<Match>& out) const;

  // The surface point is on the avatar's open boundary (beyond it, in truth).
  bool on_boundary(const geometry::SurfacePoint& p) const;
  const geometry::SurfaceQuery& neutral() const { return *surface_; }
  std::size_t shapes() const { return dims_ / 3; }
  // Template vertices matched by their response at the last search.
  std::size_t described() const;
  // The matches by response alone within `radius` of `skin` (weight 0: none), searched now.
  std::vector<Match> shape_matches(const Points& skin, double radius) const;

 private:
  void search(const Points& skin, double radius) const;  // descriptor matches near the current skin
  // The point of triangle t whose interpolated response is closest to `target`.
  geometry::SurfacePoint best_in_triangle(std::int32_t t, const float* target) const;

  Triangles triangles_;
  std::unique_ptr<geometry::SurfaceQuery> surface_;
  std::vector<uint8_t> boundary_edges_, boundary_vertex_;
  std::vector<double> data_weight_;
  std::size_t dims_ = 0;
  // Rows of dims_: the avatar's responses in its own axes, the template's in its frame and
  // turned into the avatar's axes (where they are compared: turning keeps distances).
  std::vector<float> avatar_desc_, template_desc_, template_turned_;
  std::vector<double> energy_;  // per template vertex
  // The skin vertices a search looks at: one per cell of the finest search's radius over kThin.
  std::vector<std::int32_t> candidates_;
  // Avatar vertex v's skin triangles: vertex_triangles_[first_triangle_[v] .. first_triangle_[v + 1]).
  std::vector<std::int32_t> first_triangle_, vertex_triangles_;

  // Descriptor matches, recomputed when the reach has halved since the last search.
  mutable double searched_reach_ = 0;
  mutable std::vector<Match> described_;
};

}  // namespace softdeca::fit
