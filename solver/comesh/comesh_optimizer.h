// Comesh optimization, inner loop (DESIGN "Comesh optimization", S-eq.1/2): minimise the comesh
// objective (comesh_objective.h) over every shape's interior vertices at once with L-BFGS.
//
// - Initial inverse Hessian (after Blended Cured Quasi-Newton, Zhu, Bridson & Kaufman 2018): per
//   shape i, H0_i = A_i L^{-1} / beta, L the uniform graph Laplacian of the shared topology
//   restricted to free vertices (SPD; factored once and applied to x and y of every shape), A_i
//   the rest area of shape i (the objective is area-normalized, so its Hessian scales as L / A_i;
//   a sliding boundary unknown gets its Laplacian diagonal),
//   beta = s^T y / s^T B0 s refreshed from the newest curvature pair.
// - Line search: for each triangle of each shape the largest step before its signed area reaches
//   0 is the smallest positive root of a quadratic in the step; the search starts at
//   min(1, max_step_fraction * that bound) and backtracks (Armijo). Every accepted iterate has
//   strictly positive area in every triangle of every shape.
// - Stops when (first that holds): ||g|| <= gradient_tolerance * ||g_0||; the relative decrease
//   (f_prev - f) / |f| stays below relative_decrease_tolerance for decrease_patience consecutive
//   iterations; max_iterations is reached; or the line search finds no decrease (at a minimum up
//   to round-off). Deterministic (single thread, fixed order).
//
// Unknowns, per shape: interior vertices move in 2D. With slide_boundary, a boundary vertex
// (on an edge used by one triangle) that lies strictly inside the straight segment between its two
// boundary neighbours in that shape slides along that line (one unknown); its neighbours cannot
// be passed, since the triangle on the boundary edge would have to degenerate first. So the
// domain of every shape is preserved exactly. Fixed: boundary corners, every vertex of a cohesive
// edge, vertices listed in Multimesh::boundary that are not on the topological boundary, and
// vertices used by no triangle.
//
// TODO(issue 5): sliding across polyline corners / along curved outlines (re-projection onto the
//   input outline) and pinned correspondence marks once the multimesh carries them.
// TODO(issue 5): outer topology loop applied to all shapes at once - edge flips, collapses of
//   short edges, splits - each accepted only if valid in every shape and the objective drops
//   (ComeshReport::outer counts its passes; 0 until then, vertices_after == vertices_before).
// TODO(issue 5): BCQN's gradient blending and per-triangle direction curing; CHOLMOD backend
//   (solver/core/sparse_cholesky.h) for the Laplacian; threading of the energy sum.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

struct ComeshOptions {
  double map_weight = 0.5;  // w of the objective (S-Table 1 default)
  int max_iterations = 1000;
  double gradient_tolerance = 1e-6;           // relative to the initial gradient norm
  double relative_decrease_tolerance = 1e-9;  // per iteration, (f_prev - f) / |f|
  int decrease_patience = 3;                  // consecutive small decreases before stopping
  int history = 8;                            // L-BFGS curvature pairs kept
  bool laplacian_preconditioner = true;       // false: H0 = identity (plain L-BFGS)
  bool slide_boundary = true;      // boundary vertices on straight runs slide (see above)
  double max_step_fraction = 0.8;  // line search starts at this fraction of the inversion bound
  double armijo = 1e-4;            // sufficient decrease constant c1
  int max_backtracks = 50;
  // Called after every accepted iterate (iteration >= 1) with all shapes' positions; for tests,
  // traces and visualisation. Not called for the input.
  std::function<void(int iteration, const std::vector<Points>& shapes)> on_iterate;
};

struct ComeshReport {
  int vertices_before = 0;
  int vertices_after = 0;
  int inner = 0;  // accepted L-BFGS iterations
  int outer = 0;  // topology passes (none yet, see TODO)
  double seconds = 0.0;
  double map_energy = 0.0;   // after; mean area-weighted sigma*, 2 = conformal
  double mesh_energy = 0.0;  // after; normalized ODT, 1 = equal equilateral triangles
  double map_energy_before = 0.0;
  double mesh_energy_before = 0.0;
  double objective_before = 0.0;
  double objective_after = 0.0;
  int energy_evaluations = 0;
  std::string stop_reason;  // "gradient", "decrease", "max_iterations", "line_search", "no_free"
};

// Optimizes the interior vertex positions of every shape of `mesh` (topology unchanged).
// InvalidArgument if the multimesh is inconsistent or a triangle is inverted or degenerate in
// some shape (the message names shape and triangle); Cancelled if `cancel` fires (checked every
// iteration). `progress` (may be empty) is called once per iteration; `report` may be null.
absl::StatusOr<Multimesh> OptimizeComesh(const Multimesh& mesh, const ComeshOptions& options,
                                         const CancelToken* cancel, const ProgressFn& progress,
                                         ComeshReport* report);

}  // namespace inbetween::solver
