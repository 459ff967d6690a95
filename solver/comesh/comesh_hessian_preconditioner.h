// The Newton-type initial Hessian of the comesh inner loop (comesh_preconditioner.h; DESIGN
// "Comesh optimization"). Internal to the comesh optimizer.
//
// The comesh objective's Hessian, block diagonal by shape (the mixed shape-shape MIPS blocks are
// left out) and made positive definite per triangle and shape (comesh_hessian.h: the edge-space
// 4 x 4 sum of that shape's ODT term and its two MIPS terms, projected), in the reduced unknowns
// (a slider's row is the 2D row projected on its direction). Inner iterations then grow far more
// slowly with the mesh size than with BCQN's Laplacian ("Comesh optimization: S-Table 2" in
// docs/benchmarks.md).
//
// Each shape's unknowns are contiguous in z, so every shape has its own sparse matrix and CHOLMOD
// factor (SparseCholesky::Method::kAuto: supernodal, with BLAS, where CHOLMOD finds it pays, on
// large meshes); their sparsity patterns (unknowns adjacent in the mesh) are built once per inner
// run, and Update() recomputes the values at new positions and refactors on the same patterns.
// Shapes are assembled, factored and solved on separate threads (large meshes only): each touches
// only its own block, in a fixed order, so results do not depend on the thread count.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "solver/comesh/comesh_hessian.h"
#include "solver/comesh/comesh_layout.h"
#include "solver/comesh/comesh_objective.h"
#include "solver/comesh/comesh_preconditioner.h"
#include "solver/core/cancel.h"
#include "solver/core/parallel_chunks.h"
#include "solver/core/sparse_cholesky.h"
#include "solver/core/types.h"

namespace inbetween::solver {

// The ComeshOptions fields of the same names; the defaults here are the plain model.
struct HessianPreconditionerOptions {
  // Blocks of at least this many unknowns are analysed on a helper thread that a cancel leaves
  // behind (RunCancellable); <= 0: always on the calling thread.
  int background_analysis_unknowns = 0;
  // Supernodal factors substituted in single precision (SparseCholesky::set_float_substitutions).
  bool float_substitutions = false;
  // Each triangle's MIPS blocks get mips_damping times their Gershgorin bound on the diagonal
  // before the projection (ComeshOptions::mips_damping says why).
  double mips_damping = 0.0;
};

class HessianPreconditioner : public ComeshPreconditioner {
 public:
  // Builds the patterns and factors the blocks at `shapes`. Keeps references to `triangles`,
  // `layout` and `objective`. Each shape's SparseCholesky is taken from (or added to) *factors.
  // Cancelled if `cancel` was set: the set-up's loops poll it every 4096 items (at 311k
  // vertices the pattern took ~0.56 s, the node graph and matrix ~0.37 s, the neighbour lists
  // ~0.12 s), and so do the assembly and factorization (see Refactor).
  static absl::StatusOr<std::unique_ptr<HessianPreconditioner>> Create(
      const std::vector<Triangle>& triangles, const ComeshLayout& layout,
      const ComeshObjective& objective, const std::vector<Points>& shapes,
      HessianPreconditionerOptions options, const CancelToken* cancel, SharedFactors* factors);

  bool follows_positions() const override { return true; }
  absl::Status Update(const std::vector<Points>& shapes, const CancelToken* cancel) override {
    return Refactor(shapes, /*analyze=*/false, cancel);
  }

  // H0 g; an empty vector if `cancel` was set during the solves (each shape's solve polls it).
  Eigen::VectorXd ApplyInverse(const Eigen::VectorXd& g, const CancelToken* cancel) const override;
  // H x; empty if `cancel` was set. Each block's product runs over spans of kApplyColumns columns
  // with a poll before each (one product took ~0.1 s at 311k vertices); Eigen accumulates a
  // column-major product column by column, so the sums are the same, in the same order.
  Eigen::VectorXd Apply(const Eigen::VectorXd& x, const CancelToken* cancel) const override;

 private:
  struct Block {
    // The vertex graph (see BuildNodeGraphs): node k's first unknown, and its upper-triangle
    // pattern.
    std::vector<int> node_unknowns, node_outer, node_inner;
    // Shared with a symbolic analysis left running after a cancel (Analyze).
    std::shared_ptr<Eigen::SparseMatrix<double>> matrix;
    std::shared_ptr<SparseCholesky> solver;
    absl::Status status;
  };
  struct VertexNeighbours;
  // Column-major patterns of the shapes' blocks: outer[s] (column starts), inner[s] (rows).
  struct Patterns {
    std::vector<std::vector<int>> outer, inner;
  };

  HessianPreconditioner(const std::vector<Triangle>& triangles, const ComeshLayout& layout,
                        const ComeshObjective& objective, HessianPreconditionerOptions options)
      : triangles_(&triangles), layout_(&layout), objective_(&objective), options_(options) {}

  static absl::Status SetUpCancelled() {
    return absl::CancelledError("comesh Hessian set-up cancelled");
  }

  // The phases of Create, in order; each returns false if `cancel` was set.
  bool BuildPatterns(const VertexNeighbours& nbrs, const CancelToken* cancel, Patterns* patterns);
  bool BuildNodeGraphs(const VertexNeighbours& nbrs, const CancelToken* cancel);
  bool AllocateBlocks(Patterns* patterns, const CancelToken* cancel, SharedFactors* factors);

  template <typename F>
  void ForEachShape(F&& f) const {
    ParallelChunks(
        static_cast<int>(blocks_.size()), 1, threads_, [&](int s, int, int) { f(s); },
        /*min_parallel=*/2);
  }

  // Assembles every block at `shapes` (with `analyze`, analyses its pattern first) and factors
  // it. Polls `cancel` before each step and inside the factorizations
  // (SparseCholesky::Factorize), so a cancelled set-up ends within one step: assembly or analysis
  // of one shape (tens of ms at 35k vertices) or one supernode.
  absl::Status Refactor(const std::vector<Points>& shapes, bool analyze, const CancelToken* cancel);
  static absl::Status Analyze(Block* block, int background, const CancelToken* cancel);
  // Returns false (block partly assembled) if `cancel` was set: polled at the first triangle and
  // every 4096 after it.
  bool AssembleShape(int s, const std::vector<Points>& shapes, const CancelToken* cancel);
  // Triangle t's corner Hessian in shape s: its ODT term and the two MIPS terms of s (damped),
  // projected positive definite.
  Matrix6 TriangleHessian(int s, const Triangle& t, const std::vector<Points>& shapes) const;

  const std::vector<Triangle>* triangles_ = nullptr;
  const ComeshLayout* layout_ = nullptr;
  const ComeshObjective* objective_ = nullptr;
  HessianPreconditionerOptions options_;
  std::vector<int> begin_;  // shape s: unknowns [begin_[s], begin_[s + 1])
  std::vector<Block> blocks_;
  int threads_ = 1;
};

}  // namespace inbetween::solver
