// The comesh inner loop (comesh_optimizer.h, "Inner loop"): L-BFGS after Blended Cured
// Quasi-Newton (Zhu, Bridson & Kaufman 2018) over every shape's vertices at once, on a fixed
// topology. Internal to the comesh optimizer; the outer loop (comesh_optimizer.cpp) calls it
// between topology passes.
//
// One iteration, in order:
// - the direction: the two-loop recursion (comesh_lbfgs.h) with the initial Hessian of
//   comesh_preconditioner.h, restarted from the preconditioned gradient (then -g) where it does
//   not descend;
// - curing (comesh_cure.h), kept only if the cured direction still descends;
// - the inversion bound t_max (comesh_step_bound.h); outline sliders whose own move would take a
//   chord beyond the outline guard's bound keep still for the iteration (OutlineGuard);
// - the line search: from min(1, max_step_fraction * t_max), backtracking by the minimizer of
//   the quadratic through f, the slope and the trial (clamped to [0.1, 0.5] of the step) until
//   Armijo holds; a trial that breaks the outline guard is halved. The bound is first order for
//   outline sliders across a soft corner; the trial's own evaluation, infinite for any
//   non-positive triangle, keeps every accepted iterate strictly positive in every shape;
// - the blended curvature pair (comesh_lbfgs.h);
// - local relaxation after a step shorter than the unit step (comesh_relax.h);
// - the stopping tests (ComeshOptions: gradient, decrease window, max_iterations).
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "solver/comesh/comesh_objective.h"
#include "solver/comesh/comesh_optimizer.h"
#include "solver/comesh/comesh_outline.h"
#include "solver/comesh/comesh_pairing.h"
#include "solver/comesh/comesh_preconditioner.h"
#include "solver/core/cancel.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

// Seconds since construction or the previous Lap().
class Stopwatch {
 public:
  double Lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// Accumulated over the inner runs of one optimization.
struct ComeshInnerStats {
  int iterations = 0;   // accepted iterations
  int evaluations = 0;  // full objective evaluations
  ComeshPhaseSeconds phases;
  std::string stop_reason;  // of the last run (ComeshReport::stop_reason)
  ComeshEnergies energies;  // after the last run
  double objective = 0.0;   // after the last run
};

// The outline guard's reference and bound per shape (ComeshOptions::outline_tolerance).
struct OutlineGuardBounds {
  std::vector<const ShapeOutline*> reference;
  std::vector<double> tolerance;
};

// What an inner run takes besides the multimesh and its options; pointers are not owned.
struct InnerRunContext {
  int threads = 1;  // resolved (ComeshOptions::threads)
  // The shapes' reference outlines when the boundary slides along them (the second stage; see
  // "Unknowns" in comesh_optimizer.h), else null.
  const std::vector<ShapeOutline>* outlines = nullptr;
  // With `outlines`: the outline guard's references and bounds, or null for no guard.
  const OutlineGuardBounds* bounds = nullptr;
  // The input's boundary pairing the sliders keep to (ComeshOptions::slide_window), or null.
  const BoundaryPairing* pairing = nullptr;
  const CancelToken* cancel = nullptr;
  const ProgressFn* progress = nullptr;  // called once per accepted iteration if set
  // Accepted iterations before this run: callbacks and messages number iterations globally.
  int iteration_base = 0;
  SharedFactors* factors = nullptr;  // the Hessian model's factors, kept across runs
};

// Runs the inner loop on `mesh` (valid: every triangle positive in every shape), optimizing
// mesh->shapes in place, for at most options.max_iterations iterations. Adds to *stats and sets
// its stop reason and final energies. Cancelled (naming the global iteration) if the token is seen
// set: at the start of every iteration, after each of its phases, before and after every trial of
// the line search, and inside the set-up, the direction's solves and products, curing and every
// objective evaluation.
absl::Status RunComeshInnerLoop(Multimesh* mesh, const ComeshOptions& options,
                                const InnerRunContext& context, ComeshInnerStats* stats);

}  // namespace inbetween::solver
