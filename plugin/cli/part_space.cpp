#include "part_space.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <stdexcept>

#include "mesh_io.h"

namespace softdeca::cli {

PartSpace::PartSpace(const std::vector<AvatarPart>& parts, const std::vector<std::int32_t>& triangles, std::size_t vertex_count)
    : triangles_(triangles), vertex_count_(vertex_count), buffer_(3 * vertex_count) {
  using Matrix = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
  for (const AvatarPart& p : parts) {
    if (p.first_vertex + p.vertex_count > vertex_count || 3 * (p.first_triangle + p.triangle_count) > triangles.size())
      throw std::logic_error("part '" + p.name + "' lies outside the mesh");
    Part part;
    part.name = p.name;
    part.first = p.first_vertex;
    part.count = p.vertex_count;
    part.first_triangle = p.first_triangle;
    const Matrix m = Eigen::Map<const Matrix>(p.transform);
    part.identity = m.isIdentity(0.0);
    const Matrix inverse = m.inverse();
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(part.inverse) = inverse.topRows<3>();
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(part.linear) = m.topLeftCorner<3, 3>();
    // The joined mesh turned a mirrored part's triangles over; its own mesh has them as the file.
    if (p.mirrored)
      for (std::size_t t = p.first_triangle; t < p.first_triangle + p.triangle_count; ++t) std::swap(triangles_[3 * t + 1], triangles_[3 * t + 2]);
    parts_.push_back(part);
  }
}

const float* PartSpace::to_local(const float* common) {
  std::copy(common, common + 3 * vertex_count_, buffer_.begin());
  for (const Part& p : parts_) {
    if (p.identity) continue;
    const Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> inv(p.inverse);
    for (std::size_t i = p.first; i < p.first + p.count; ++i) {
      const Eigen::Vector3d q = inv.leftCols<3>() * Eigen::Vector3f(common + 3 * i).cast<double>() + inv.col(3);
      for (int k = 0; k < 3; ++k) buffer_[3 * i + static_cast<std::size_t>(k)] = static_cast<float>(q[k]);
    }
  }
  return buffer_.data();
}

void PartSpace::write_obj(const std::string& path, const float* common, const float* normals, const std::string& comment) {
  std::vector<ObjGroup> groups;
  if (parts_.size() > 1)
    for (const Part& p : parts_) groups.push_back({p.name, p.first_triangle});
  if (normals) {
    normals_.assign(normals, normals + 3 * vertex_count_);
    for (const Part& p : parts_) {
      if (p.identity) continue;
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> linear(p.linear);
      for (std::size_t i = p.first; i < p.first + p.count; ++i) {
        const Eigen::Vector3d n = (linear.transpose() * Eigen::Vector3f(normals + 3 * i).cast<double>()).normalized();
        for (int k = 0; k < 3; ++k) normals_[3 * i + static_cast<std::size_t>(k)] = static_cast<float>(n[k]);
      }
    }
  }
  cli::write_obj(path, to_local(common), vertex_count_, normals ? normals_.data() : nullptr, triangles_.data(), triangles_.size() / 3,
                 comment, groups);
}

}  // namespace softdeca::cli
