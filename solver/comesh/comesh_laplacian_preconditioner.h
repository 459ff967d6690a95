// BCQN's initial Hessian for the comesh inner loop (comesh_preconditioner.h; Zhu, Bridson &
// Kaufman 2018). Internal to the comesh optimizer.
//
// The uniform graph Laplacian L of the shared topology, restricted to the vertices that are
// movable in EVERY shape (interior vertices and vertices that slide in every shape; all others
// act as Dirichlet values), factored ONCE as a scalar matrix with CHOLMOD and applied to x and y
// of every shape in one multi-column solve. Shape s's block of B0^{-1} is A_s J_s^T L^{-1} J_s,
// J_s lifting a slider's scalar to 2D along its direction (projection onto the slider tangent
// after the solve), so the model is SPD on the reduced unknowns without ever coupling x and y in
// the factor. Unknowns of vertices that are movable in some shapes only get the Jacobi value
// A_s / deg(v) (deg = L's diagonal). The forward operator B0 is the matching J_s^T L J_s / A_s
// product, and deg(v) / A_s on the Jacobi unknowns.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/comesh/comesh_layout.h"
#include "solver/comesh/comesh_preconditioner.h"
#include "solver/core/cancel.h"
#include "solver/core/sparse_cholesky.h"
#include "solver/core/types.h"

namespace inbetween::solver {

class LaplacianPreconditioner : public ComeshPreconditioner {
 public:
  // `areas`: each shape's rest area A_s. Keeps a reference to `layout`. Cancelled if `cancel` was
  // set during the factorization.
  static absl::StatusOr<std::unique_ptr<LaplacianPreconditioner>> Create(
      const std::vector<Triangle>& triangles, const ComeshLayout& layout, std::vector<double> areas,
      const CancelToken* cancel);

  Eigen::VectorXd ApplyInverse(const Eigen::VectorXd& g, const CancelToken* cancel) const override;
  // Does not poll `cancel` (one sparse product).
  Eigen::VectorXd Apply(const Eigen::VectorXd& x, const CancelToken* cancel) const override;

 private:
  LaplacianPreconditioner() = default;

  // The components of L's graph (compact vertices joined by mesh edges) with no edge to a
  // Dirichlet vertex: every vertex there moves in every shape (outline sliding round a whole
  // loop, past soft corners only), so L is singular on them, its null vector the component's
  // constant (a translation, which its closed loop of sliders cannot follow). Their rows in
  // floating_rows_, one run per component (floating_begin_).
  void FindFloating(const std::vector<Triangle>& triangles);
  // Projects every column of `m` (rows = L's) onto the complement of the floating components'
  // constants: L's pseudo-inverse there instead of the regularized inverse, whose constant part
  // (~1e8 times the rest) would swamp the direction.
  void RemoveFloatingMeans(Eigen::MatrixXd* m) const;

  std::vector<double> areas_;
  const ComeshLayout* layout_ = nullptr;
  int size_ = 0;
  std::vector<int> compact_;    // vertex -> row of L, or -1
  std::vector<double> degree_;  // L's diagonal over all vertices (Jacobi fallback)
  std::vector<int> floating_rows_, floating_begin_;  // see FindFloating
  Eigen::SparseMatrix<double> matrix_;
  std::unique_ptr<SparseCholesky> solver_;  // null while L is empty
};

}  // namespace inbetween::solver
