// The comesh inner loop's L-BFGS after Blended Cured Quasi-Newton (Zhu, Bridson & Kaufman 2018;
// comesh_optimizer.h, "Inner loop"): the two-loop recursion with H0 = B0^{-1} / beta and the
// blended curvature pairs. Internal to the comesh optimizer.
//
// - scaling: beta = s^T y / s^T B0 s from the newest pair (or y^T B0^{-1} y / s^T y with
//   scaling_by_inverse).
// - blending: y <- (1 - theta) y + theta beta B0 s with theta = min(1, blend ||g|| / ||g_0||):
//   the model (Sobolev, far from the minimum) dominates early, measured curvature near the
//   minimum. Both have curvature s^T y along s, so a blended pair stays positive.
#pragma once

#include <Eigen/Core>
#include <deque>

#include "solver/comesh/comesh_preconditioner.h"
#include "solver/core/cancel.h"

namespace inbetween::solver {

// The ComeshOptions fields of the same names.
struct LbfgsOptions {
  int history = 8;                  // curvature pairs kept; 0: none (steepest descent in B0)
  bool scaling_by_inverse = false;  // beta = y^T B0^{-1} y / s^T y (else s^T y / s^T B0 s)
  double blend = 1.0;               // blending strength (0: the measured pairs alone)
};

class ComeshLbfgs {
 public:
  explicit ComeshLbfgs(LbfgsOptions options) : options_(options) {}

  // The search direction -H g. Empty if `cancel` was set: polled before each pair's vector
  // operations and at the end (the whole recursion, solves aside, took ~0.1 s at 311k vertices
  // between two polls), and inside B0's solve.
  Eigen::VectorXd Direction(const Eigen::VectorXd& g, const ComeshPreconditioner& b0,
                            const CancelToken* cancel) const;
  // Forgets every pair (beta stays): the next direction is the preconditioned gradient.
  void Clear() { pairs_.clear(); }
  // Records the accepted step z -> z_new with gradients g -> g_new (g0: the run's initial
  // gradient norm, for the blending) if its curvature s^T y is positive enough. False if
  // `cancel` was set (polled after each vector operation and inside B0's products).
  bool Update(const Eigen::VectorXd& z, const Eigen::VectorXd& z_new, const Eigen::VectorXd& g,
              const Eigen::VectorXd& g_new, double g0, const ComeshPreconditioner& b0,
              const CancelToken* cancel);

 private:
  struct Pair {
    Eigen::VectorXd s, y;
    double rho;
  };

  LbfgsOptions options_;
  std::deque<Pair> pairs_;
  // Storage for the next pair: that of the pair last dropped from the history (or not kept), as
  // two fresh vectors every iteration cost ~30 ms of page faults at 311k vertices.
  Pair spare_{};
  double beta_ = 1.0;
};

}  // namespace inbetween::solver
