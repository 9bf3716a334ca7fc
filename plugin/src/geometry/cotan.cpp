#include "geometry/cotan.h"

#include <vector>

namespace softdeca::geometry {
namespace {
using Vec3 = Eigen::Vector3d;
Vec3 vtx(const TriPoints& v, int32_t i) { return v.row(i).transpose(); }
// cot of the angle between u and w; guarded against degenerate (zero-area) corners.
double cot(const Vec3& u, const Vec3& w) {
  const double s = u.cross(w).norm();
  return s > 1e-300 ? u.dot(w) / s : 0.0;
}
}  // namespace

Eigen::SparseMatrix<double> cotan_laplacian(const TriPoints& v, const Triangles& f) {
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<std::size_t>(f.rows()) * 12);
  for (Eigen::Index t = 0; t < f.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int32_t i = f(t, k), j = f(t, (k + 1) % 3), o = f(t, (k + 2) % 3);
      const double w = 0.5 * cot(vtx(v, i) - vtx(v, o), vtx(v, j) - vtx(v, o));
      trip.emplace_back(i, j, w);
      trip.emplace_back(j, i, w);
      trip.emplace_back(i, i, -w);
      trip.emplace_back(j, j, -w);
    }
  }
  Eigen::SparseMatrix<double> L(v.rows(), v.rows());
  L.setFromTriplets(trip.begin(), trip.end());
  return L;
}

Eigen::VectorXd voronoi_areas(const TriPoints& v, const Triangles& f) {
  Eigen::VectorXd area = Eigen::VectorXd::Zero(v.rows());
  for (Eigen::Index t = 0; t < f.rows(); ++t) {
    const int32_t id[3] = {f(t, 0), f(t, 1), f(t, 2)};
    const Vec3 p[3] = {vtx(v, id[0]), vtx(v, id[1]), vtx(v, id[2])};
    const double A = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (A <= 0) continue;
    int obtuse = -1;
    for (int k = 0; k < 3; ++k)
      if ((p[(k + 1) % 3] - p[k]).dot(p[(k + 2) % 3] - p[k]) < 0) obtuse = k;
    if (obtuse >= 0) {
      for (int k = 0; k < 3; ++k) area[id[k]] += (k == obtuse ? 0.5 : 0.25) * A;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      // Vertex k's Voronoi share: edges k-(k+1) and k-(k+2) weighted by the opposite cotangents.
      const Vec3& a = p[k];
      const Vec3& b = p[(k + 1) % 3];
      const Vec3& c = p[(k + 2) % 3];
      area[id[k]] += ((b - a).squaredNorm() * cot(a - c, b - c) +
                      (c - a).squaredNorm() * cot(a - b, c - b)) / 8.0;
    }
  }
  return area;
}

}  // namespace softdeca::geometry
