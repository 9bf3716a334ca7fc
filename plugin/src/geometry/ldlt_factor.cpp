#include "geometry/ldlt_factor.h"

#include <Eigen/SparseCholesky>
#ifdef SOFTDECA_HAVE_METIS
#include <iostream>  // Eigen's MetisSupport uses std::cerr without including it
#include <Eigen/MetisSupport>
#endif

namespace softdeca::geometry {

namespace {
#ifdef SOFTDECA_HAVE_METIS
using FillReducingOrdering = Eigen::MetisOrdering<int>;
#else
using FillReducingOrdering = Eigen::AMDOrdering<int>;
#endif
}  // namespace

// Eigen keeps the stored L and D protected: matrixL() wraps L in a temporary unit-lower view and
// vectorD() returns a copy.
struct LdltFactor::Impl : Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, FillReducingOrdering> {
  const Eigen::SparseMatrix<double>& stored_lower() const { return m_matrix; }
  const Eigen::VectorXd& stored_diagonal() const { return m_diag; }
};

LdltFactor::LdltFactor(const Eigen::SparseMatrix<double>& K) : impl_(std::make_unique<Impl>()) { impl_->compute(K); }

LdltFactor::~LdltFactor() = default;

bool LdltFactor::ok() const { return impl_->info() == Eigen::Success; }

const Eigen::SparseMatrix<double>& LdltFactor::lower() const { return impl_->stored_lower(); }

const Eigen::VectorXd& LdltFactor::diagonal() const { return impl_->stored_diagonal(); }

const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>& LdltFactor::permutation() const {
  return impl_->permutationP();
}

const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>& LdltFactor::inverse_permutation() const {
  return impl_->permutationPinv();
}

}  // namespace softdeca::geometry
