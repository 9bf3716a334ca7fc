// Discrete differential operators on triangle meshes: the cotangent Laplacian and the mass
// matrix. The skull's bending energy (Laplacian with rotation) and mesh smoothing use them.
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <cstdint>

namespace softdeca::geometry {

using TriPoints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Symmetric cotangent Laplacian L with L_ij = (cot a_ij + cot b_ij) / 2 off the diagonal and
// rows summing to zero (negative semi-definite). Boundary edges take their single angle.
Eigen::SparseMatrix<double> cotan_laplacian(const TriPoints& v, const Triangles& f);

// Lumped mass matrix with mixed Voronoi areas (Meyer et al. 2003): the diagonal sums to the
// surface area, and obtuse triangles give their vertices barycentric-style shares.
Eigen::VectorXd voronoi_areas(const TriPoints& v, const Triangles& f);

}  // namespace softdeca::geometry
