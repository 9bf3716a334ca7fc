#include "geometry/rigid.h"

#include <Eigen/Dense>

namespace softdeca::geometry {

namespace {
template <class Get>
Similarity fit(Get src, Get dst, std::size_t n, bool with_scale) {
  Eigen::Vector3d ms = Eigen::Vector3d::Zero(), md = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    ms += src(i);
    md += dst(i);
  }
  ms /= static_cast<double>(n);
  md /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double var = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = src(i) - ms, b = dst(i) - md;
    cov += b * a.transpose();
    var += a.squaredNorm();
  }
  cov /= static_cast<double>(n);
  var /= static_cast<double>(n);
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d d(1, 1, 1);
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) d[2] = -1;
  const Eigen::Matrix3d r = svd.matrixU() * d.asDiagonal() * svd.matrixV().transpose();
  Similarity s;
  s.scale = with_scale && var > 0 ? svd.singularValues().dot(d) / var : 1.0;
  const Eigen::Vector3d t = md - s.scale * r * ms;
  for (int i = 0; i < 3; ++i) {
    s.translation[i] = t[i];
    for (int j = 0; j < 3; ++j) s.rotation[3 * i + j] = r(i, j);
  }
  return s;
}
}  // namespace

Similarity fit_similarity(const float* src, const int* src_index, const float* dst, const int* dst_index, std::size_t n,
                          bool with_scale) {
  const auto get = [](const float* p, const int* index) {
    return [p, index](std::size_t i) {
      const std::size_t k = 3 * static_cast<std::size_t>(index ? index[i] : static_cast<int>(i));
      return Eigen::Vector3d(p[k], p[k + 1], p[k + 2]);
    };
  };
  auto s = get(src, src_index);
  auto d = get(dst, dst_index);
  return fit<decltype(s)>(s, d, n, with_scale);
}

Similarity fit_similarity(const double* src, const double* dst, std::size_t n, bool with_scale) {
  const auto get = [](const double* p) { return [p](std::size_t i) { return Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]); }; };
  auto s = get(src);
  auto d = get(dst);
  return fit<decltype(s)>(s, d, n, with_scale);
}

}  // namespace softdeca::geometry
