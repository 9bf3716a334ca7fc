#include "surface_points.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "geometry/surface_query.h"

namespace softdeca::cli {

SurfacePoints::SurfacePoints(const float* vertices, std::size_t vertex_count, const std::vector<std::int32_t>& triangles,
                             const float* points, std::size_t point_count) {
  if (triangles.empty()) throw std::invalid_argument("points on a surface need a mesh with triangles");
  geometry::Points v = Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>>(
                           vertices, static_cast<Eigen::Index>(vertex_count), 3)
                           .cast<double>();
  geometry::Triangles f = Eigen::Map<const geometry::Triangles>(triangles.data(), static_cast<Eigen::Index>(triangles.size() / 3), 3);
  const geometry::SurfaceQuery surface(std::move(v), std::move(f));  // checks the indices
  for (std::size_t k = 0; k < point_count; ++k) {
    const geometry::SurfacePoint p = surface.closest(Eigen::Vector3f(points + 3 * k).cast<double>());
    for (int j = 0; j < 3; ++j) {
      corners_.push_back(surface.triangles()(p.triangle, j));
      weights_.push_back(static_cast<float>(p.bary[j]));
    }
    max_distance_ = std::max(max_distance_, std::sqrt(p.squared_distance));
  }
}

void SurfacePoints::evaluate(const float* vertices, float* out) const {
  for (std::size_t k = 0; k < size(); ++k)
    for (int c = 0; c < 3; ++c) {
      float sum = 0;
      for (std::size_t j = 0; j < 3; ++j)
        sum += weights_[3 * k + j] * vertices[3 * static_cast<std::size_t>(corners_[3 * k + j]) + static_cast<std::size_t>(c)];
      out[3 * k + static_cast<std::size_t>(c)] = sum;
    }
}

}  // namespace softdeca::cli
