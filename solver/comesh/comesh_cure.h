// BCQN curing of a comesh search direction (comesh_inner_loop.h; Zhu, Bridson & Kaufman 2018).
// Internal to the comesh optimizer.
//
// For every triangle of every shape, the linearised doubled area along d is c0 + c1 t. If the
// unit step would shrink it below cure_keep * c0, the displacements of its moving corners are
// scaled by (1 - cure_keep) c0 / (-c1): the factor that keeps the linearised area at
// cure_keep * c0 if all corners are scaled alike; a vertex takes the smallest factor of its
// triangles. A few blocking triangles then no longer shrink the step of the whole mesh (the
// exact quadratic area and repeated passes measured worse, docs/benchmarks.md).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "solver/comesh/comesh_layout.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"

namespace inbetween::solver {

// Cures *d in place and returns the number of scaled unknowns; `disp` is scratch and holds the
// displacements of the uncured d afterwards (ComeshLayout::Displacements). -1 (d untouched) if
// `cancel` was set: polled before each chunk of triangles (the whole took up to ~0.14 s at 311k
// vertices between two polls). Per triangle in parallel, then per vertex in triangle order: the
// result does not depend on `threads`.
int CureDirection(const std::vector<Triangle>& triangles, const std::vector<Points>& shapes,
                  const ComeshLayout& layout, double cure_keep, int threads,
                  const CancelToken* cancel, std::vector<Points>* disp, Eigen::VectorXd* d);

}  // namespace inbetween::solver
