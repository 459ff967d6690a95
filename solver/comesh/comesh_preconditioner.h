// The initial Hessian B0 of the comesh inner loop's L-BFGS (comesh_optimizer.h, "Inner loop"),
// behind one interface over its models. Internal to the comesh optimizer.
//
// - HessianPreconditioner (comesh_hessian_preconditioner.h): the objective's Hessian, block
//   diagonal by shape; a Newton-type model, for at most ComeshOptions::hessian_max_shapes shapes.
// - LaplacianPreconditioner (comesh_laplacian_preconditioner.h): BCQN's model, the uniform graph
//   Laplacian scaled by each shape's area; for more shapes (the block-diagonal Hessian drops the
//   coupling between shapes, which matters more the more there are: S-Table 3 in
//   docs/benchmarks.md).
// - the identity (plain L-BFGS) with ComeshOptions::laplacian_preconditioner off.
// The L-BFGS recursion uses H0 = B0^{-1} / beta (comesh_lbfgs.h).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "solver/comesh/comesh_layout.h"
#include "solver/comesh/comesh_objective.h"
#include "solver/comesh/comesh_optimizer.h"
#include "solver/core/cancel.h"
#include "solver/core/sparse_cholesky.h"
#include "solver/core/types.h"

namespace inbetween::solver {

class ComeshPreconditioner {
 public:
  virtual ~ComeshPreconditioner() = default;

  // B0^{-1} g (H0 without the scalar 1 / beta); an empty vector if `cancel` was set during the
  // solve.
  virtual Eigen::VectorXd ApplyInverse(const Eigen::VectorXd& g,
                                       const CancelToken* cancel) const = 0;
  // B0 x (for the curvature scaling and blending); an empty vector if `cancel` was set.
  virtual Eigen::VectorXd Apply(const Eigen::VectorXd& x, const CancelToken* cancel) const = 0;

  // True if the model depends on the positions, so that Update follows them
  // (ComeshOptions::hessian_refresh).
  virtual bool follows_positions() const { return false; }
  // Rebuilds the model at `shapes` (same topology and layout); Cancelled if `cancel` was set.
  virtual absl::Status Update(const std::vector<Points>& shapes, const CancelToken* cancel) {
    return absl::OkStatus();
  }
};

// Each shape's SparseCholesky, kept from one inner run to the next: a new analysis then reuses
// the previous factor's value array (hundreds of MB at 311k vertices, its pages already mapped;
// see SparseCholesky) instead of allocating and faulting in a new one.
using SharedFactors = std::vector<std::shared_ptr<SparseCholesky>>;

// The model `options` choose for this multimesh (see above), set up at `shapes` for `layout`'s
// unknowns; every argument must outlive the result. `factors` carries the Hessian model's
// factorizations across inner runs. Cancelled if `cancel` was set during the set-up (its loops
// and factorizations poll it).
absl::StatusOr<std::unique_ptr<ComeshPreconditioner>> CreateComeshPreconditioner(
    const std::vector<Triangle>& triangles, const ComeshLayout& layout,
    const ComeshObjective& objective, const std::vector<Points>& shapes,
    const ComeshOptions& options, const CancelToken* cancel, SharedFactors* factors);

}  // namespace inbetween::solver
