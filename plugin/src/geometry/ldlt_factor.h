// The sparse LDL^T factorisation the simulator's and the runtime's solvers share:
// P K P^T = L D L^T with a fill-reducing ordering P, METIS nested dissection where the library
// was built with it (11% fewer factor nonzeros than AMD on the template's skin, about 30% less
// fill on layered heads, and a small top separator for the runtime's two-thread split), else
// AMD. Each solver keeps its own substitutions over the factor.
#pragma once

#include <Eigen/SparseCore>

#include <memory>

namespace softdeca::geometry {

class LdltFactor {
 public:
  // K symmetric, its lower triangle read. ok() tells whether the factorisation succeeded.
  explicit LdltFactor(const Eigen::SparseMatrix<double>& K);
  ~LdltFactor();
  LdltFactor(const LdltFactor&) = delete;
  LdltFactor& operator=(const LdltFactor&) = delete;

  bool ok() const;
  // L strictly lower, column-major (the unit diagonal implied), D, and P (Eigen's layout:
  // (P b)[P.indices()[i]] = b[i]).
  const Eigen::SparseMatrix<double>& lower() const;
  const Eigen::VectorXd& diagonal() const;
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>& permutation() const;
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>& inverse_permutation() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace softdeca::geometry
