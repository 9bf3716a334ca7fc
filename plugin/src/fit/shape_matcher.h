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

// One ARKit shape both meshes have: its deltas on each, in the template's frame (metres).
struct SharedShape {
  Points avatar;     // per avatar vertex
  Points template_;  // per template skin vertex
};

class ShapeMatcher {
 public:
  // `avatar`: the avatar's vertices in the template's frame; `triangles`: its skin triangles
  // with their open edges (bit k: the edge opposite corner k) and open vertices;
  // `data_weight`: per template skin vertex.
  ShapeMatcher(const Points& avatar, const Triangles& triangles, std::vector<uint8_t> boundary_edges,
               std::vector<uint8_t> boundary_vertex, std::vector<double> data_weight, const std::vector<SharedShape>& shapes);

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
  geometry::SurfacePoint best_in_triangle(std::int32_t t, const double* target) const;

  std::unique_ptr<geometry::SurfaceQuery> surface_;
  std::vector<uint8_t> boundary_edges_, boundary_vertex_;
  std::vector<double> data_weight_;
  std::size_t dims_ = 0;
  std::vector<double> avatar_desc_, template_desc_, energy_;  // rows of dims_; energy per template vertex
  std::vector<std::vector<std::int32_t>> vertex_triangles_;   // avatar vertex -> its skin triangles
  std::vector<uint8_t> avatar_skin_;                          // avatar vertex lies on a skin triangle

  // Descriptor matches, recomputed when the reach has halved since the last search.
  mutable double searched_reach_ = 0;
  mutable std::vector<Match> described_;
};

}  // namespace softdeca::fit
