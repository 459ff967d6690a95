// The choice of the comesh inner loop's initial Hessian (see comesh_preconditioner.h).
#include "solver/comesh/comesh_preconditioner.h"

#include <utility>

#include "solver/comesh/comesh_hessian_preconditioner.h"
#include "solver/comesh/comesh_laplacian_preconditioner.h"

namespace inbetween::solver {
namespace {

// B0 = identity: plain L-BFGS (ComeshOptions::laplacian_preconditioner off).
class IdentityPreconditioner : public ComeshPreconditioner {
 public:
  Eigen::VectorXd ApplyInverse(const Eigen::VectorXd& g, const CancelToken*) const override {
    return g;
  }
  Eigen::VectorXd Apply(const Eigen::VectorXd& x, const CancelToken*) const override { return x; }
};

}  // namespace

absl::StatusOr<std::unique_ptr<ComeshPreconditioner>> CreateComeshPreconditioner(
    const std::vector<Triangle>& triangles, const ComeshLayout& layout,
    const ComeshObjective& objective, const std::vector<Points>& shapes,
    const ComeshOptions& options, const CancelToken* cancel, SharedFactors* factors) {
  if (options.hessian_preconditioner && layout.num_shapes() <= options.hessian_max_shapes) {
    return HessianPreconditioner::Create(
        triangles, layout, objective, shapes,
        {.background_analysis_unknowns = options.background_analysis_unknowns,
         .float_substitutions = options.float_substitutions,
         .mips_damping = options.mips_damping},
        cancel, factors);
  }
  if (!options.laplacian_preconditioner) return std::make_unique<IdentityPreconditioner>();
  std::vector<double> areas;
  for (int s = 0; s < layout.num_shapes(); ++s) areas.push_back(objective.rest_area(s));
  return LaplacianPreconditioner::Create(triangles, layout, std::move(areas), cancel);
}

}  // namespace inbetween::solver
