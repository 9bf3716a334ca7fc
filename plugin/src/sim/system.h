// The global step of projective dynamics: the stacked constraints G (rows x vertices) with
// weights W give the normal equations (G^T W G) x = G^T W P + f. Pinned bone vertices are
// moved to the right-hand side, and the matrix over the free vertices is factorised once
// (the sparse LDL^T of geometry/ldlt_factor.h) and reused for every iteration and every frame
// until weights or topology change. The x, y and z columns share the matrix: one factorisation, three solves.
#pragma once

#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "geometry/ldlt_factor.h"
#include "sim/constraints.h"
#include "sim/model.h"
#include "sim/thread_pool.h"

namespace softdeca::sim {

using RowMajorSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

class System {
 public:
  // `extra` (collision contacts) are appended after the model's rows as constant rows.
  explicit System(const Model& model, const ConstraintGroup* extra = nullptr);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  Eigen::Index free_count() const { return static_cast<Eigen::Index>(free_.size()); }
  const std::vector<int32_t>& free_vertices() const { return free_; }
  Eigen::Index rows() const { return rows_; }
  Eigen::Index variable_rows() const { return variable_rows_; }
  // Proximal weight mu (tiny): (A + mu I) x_{k+1} = b + mu x_k keeps A definite even where a
  // part of the mesh is held by nothing, without moving any fixed point.
  double proximal() const { return mu_; }

  // Per frame: G^T W (P_const - G_pinned x_pinned) over the constant rows plus the pinned
  // vertices' share of the projecting rows, plus the free vertices' forces.
  Positions frame_rhs(const Positions& P, const Positions& x, const Positions& force) const;
  // Per iteration: frame_rhs + J_var P_var + mu x_free, rows split over the pool.
  void iteration_rhs(const Positions& P, const Positions& frame, const Positions& x_free, Positions& out,
                     ThreadPool* pool) const;
  // Solves (A + mu I) X = B for the three columns in one pass over the factor per triangle
  // (the factor's memory traffic, not arithmetic, bounds the solve).
  void solve(const Positions& B, Positions& X) const;

  double factor_seconds() const { return factor_seconds_; }

 private:
  Eigen::Index rows_ = 0, variable_rows_ = 0;
  std::vector<int32_t> free_;        // free vertex list
  std::vector<int32_t> free_index_;  // vertex -> free index, -1 when pinned
  std::vector<int32_t> pinned_;      // pinned vertex list
  RowMajorSparse J_;      // G_free^T W over all rows (free x rows)
  RowMajorSparse J_var_;  // its first variable_rows_ columns
  RowMajorSparse G_pin_;  // G over the pinned columns (rows x pinned)
  std::unique_ptr<geometry::LdltFactor> factor_;
  double mu_ = 0;
  double factor_seconds_ = 0;
};

}  // namespace softdeca::sim
