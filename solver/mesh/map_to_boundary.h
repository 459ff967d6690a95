// Injective map of a triangle mesh into a new boundary: Tutte embedding for convex targets (and
// tried for any target), otherwise a LIM-style progressive boundary pull under a symmetric
// Dirichlet barrier.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct MapToBoundaryOptions {
  // Total SLIM iterations (local-global proxy + flip-free line search) allowed.
  int max_iterations = 2000;
  // Iterations per penalty stage of the boundary pull.
  int iterations_per_stage = 60;
  // A penalty stage also ends at the first iteration that lowers the energy by less than this
  // fraction (then the penalty grows tenfold). With 1e-5 instead of 1e-7, random star-shaped pairs
  // (with and without a hole) mapped as often (468 against 465 of 699) in 35% less time; with 1e-4
  // 10 of 68 pairs with holes no longer mapped (docs/benchmarks.md).
  double stage_progress = 1e-5;
  // Interior-only iterations after the boundary is exactly on target (quality polish).
  int polish_iterations = 20;
  // Boundary vertices must be within this distance (relative to the target's bounding-box
  // diagonal) of their target before the final exact placement.
  double boundary_tolerance = 1e-6;
  // Try the mean-value Tutte embedding first when the target boundary is convex.
  bool tutte_when_convex = true;
  // Also try it when the target is not convex (or has several loops), and keep it when no
  // triangle folds (then only the polish runs): much cheaper than the progressive pull, which
  // remains the fallback.
  bool tutte_first_always = true;
  // Optional start of the boundary pull instead of the identity: positions of the source's
  // vertices (same order) with every triangle positive, typically the map into a similar
  // drawing (a neighbouring key). Null = start from `source`.
  const Points* start = nullptr;
};

struct MapToBoundaryReport {
  bool tutte = false;   // the result started from a convex Tutte embedding
  int iterations = 0;   // SLIM iterations
  int stages = 0;       // penalty stages of the boundary pull
  double energy = 0.0;  // area-weighted mean symmetric Dirichlet (4 = isometry)
};

// `source` is a valid mesh (all `triangles` positive), `boundary` lists its boundary vertices in
// order and `target_boundary[k]` is where boundary[k] must go. Returns positions for every
// vertex: boundary exactly on target, no triangle inverted or degenerate.
// Errors: INVALID_ARGUMENT (sizes), FAILED_PRECONDITION (no injective map found), CANCELLED,
// RESOURCE_EXHAUSTED (out of memory, naming the system being factorized when it was a solve).
absl::StatusOr<Points> MapToBoundary(const Points& source, const std::vector<Triangle>& triangles,
                                     const std::vector<int>& boundary,
                                     const Points& target_boundary,
                                     const MapToBoundaryOptions& options = {},
                                     const CancelToken* cancel = nullptr,
                                     MapToBoundaryReport* report = nullptr);

}  // namespace inbetween::solver
