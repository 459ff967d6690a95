// Coarsening of a mesh placed in several shapes at once: removable interior vertices are merged
// into a neighbour (half-edge collapse v -> u: every triangle of v's star that does not hold u
// gets u in v's place, the two that hold both are dropped) when, in every shape, each new
// triangle is positive and the thinnest of them is at least as good as the thinnest triangle of
// v's star was (quality as validate.h's TriangleQuality; with `quality_floor` > 0 the bar is
// min(that, quality_floor) instead, which trades quality above the floor for fewer vertices).
// Among the neighbours that qualify, the one whose new triangles are best wins. Positions never
// move, so every triangle of the result is a triangle of the input or made of its vertices at
// their input positions: a mesh with every triangle positive and its boundary untouched stays
// an embedding in every shape (a disk or not).
//
// Vertices are visited thinnest star first, in passes until one removes nothing (at most
// max_passes); deterministic for the same input. The link condition (u and v share exactly the
// two neighbours across their edge) keeps the mesh a manifold.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct CollapseOptions {
  double quality_floor = 0.0;  // see above; 0: a collapse never lowers the local worst quality
  int max_passes = 8;
};

struct CollapseResult {
  std::vector<Triangle> triangles;  // over the kept vertices, renumbered
  std::vector<Points> shapes;       // the kept vertices' positions, shape by shape
  // old_to_new[v]: v's index in the result, or -1 when it was merged away. Vertices below
  // first_removable keep their index.
  std::vector<int> old_to_new;
  int removed = 0;
};

// Only vertices with index >= first_removable that are interior (every edge at them borders two
// triangles) are removed. Every shape must have one point per vertex.
// Errors: INVALID_ARGUMENT (sizes, a triangle index out of range), CANCELLED.
absl::StatusOr<CollapseResult> CollapseVertices(const std::vector<Triangle>& triangles,
                                                const std::vector<Points>& shapes,
                                                int first_removable,
                                                const CollapseOptions& options = {},
                                                const CancelToken* cancel = nullptr);

}  // namespace inbetween::solver
