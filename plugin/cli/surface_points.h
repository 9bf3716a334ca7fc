// Points riding on a mesh's surface: each given point as the nearest point of the mesh at rest
// (geometry/surface_query.h), in barycentric coordinates of its triangle, evaluated on any frame
// of the mesh. The replay carries the bundle's landmarks (found on the registered template) onto
// a user's own mesh so, and reads them off that mesh's linear blend where a phone's tracked face
// would give them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace softdeca::cli {

class SurfacePoints {
 public:
  // Throws std::invalid_argument when the mesh has no triangle or one refers to a missing vertex.
  SurfacePoints(const float* vertices, std::size_t vertex_count, const std::vector<std::int32_t>& triangles,
                const float* points, std::size_t point_count);
  std::size_t size() const { return weights_.size() / 3; }
  void evaluate(const float* vertices, float* out) const;  // size() points
  double max_distance() const { return max_distance_; }    // of a point from the surface at rest

 private:
  std::vector<std::int32_t> corners_;
  std::vector<float> weights_;
  double max_distance_ = 0;
};

}  // namespace softdeca::cli
