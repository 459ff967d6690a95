// Validators for meshes and multimeshes, used by tests and by the server before it hands out a
// mesh.
#pragma once

#include <vector>

#include "absl/status/status.h"
#include "solver/core/types.h"
#include "solver/geometry/primitives.h"  // SignedArea2
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

// Number of triangles with signed area <= min_area2 / 2 (inverted or degenerate).
int CountInverted(const std::vector<Triangle>& triangles, const Points& x, double min_area2 = 0.0);

// Triangle quality 4 sqrt(3) A / (sum of squared edge lengths), A the signed area: 1 for an
// equilateral triangle, 0 for a flat one (or one with coincident corners), negative if inverted.
double TriangleQuality(const Point& a, const Point& b, const Point& c);

// The smallest TriangleQuality over `triangles` in geometry x (+inf without triangles). Sets
// *where (if given) to the index of that triangle.
double WorstTriangleQuality(const std::vector<Triangle>& triangles, const Points& x,
                            int* where = nullptr);

// No two boundary edges of the mesh cross in geometry x (a proper crossing, decided with exact
// predicates; touching and collinear overlap, as of the collocated sides of a closed cut, are
// allowed). With every triangle positive this is what is left of injectivity: a map can fold the
// boundary over itself with no triangle inverted. InvalidArgument naming the two edges and where.
// Expects valid indices. O(B) for B boundary edges of about equal length (a uniform grid).
absl::Status ValidateBoundaryDoesNotCross(const std::vector<Triangle>& triangles, const Points& x);

// Checks shared topology (indices in range, every shape has the same vertex count, each directed
// edge in one triangle only: no repeated or overlapping triangle), `boundary` vertices on the
// boundary (and `boundary` the loops' concatenation when loops are given), boundary loops and
// cohesive edges (below, when present), the art (none or one per shape, each point in a
// triangle with its corners), no inverted or degenerate triangle and no crossing
// boundary (above) in any shape. Errors name the shape and the triangle.
absl::Status ValidateMultimesh(const Multimesh& mesh);

// Boundary vertices on their boundaries: every consecutive pair of every boundary loop is an
// edge with a triangle on its left only, and the loops hold every boundary edge of the mesh, each
// once.
// OK when boundary_loops is empty.
absl::Status ValidateBoundaryLoops(const Multimesh& mesh);

// Cohesive pairs in range, and collocated (within relative_tolerance of the shape's bounding-box
// diagonal) in every shape where cohesive_closed says they are closed.
absl::Status ValidateCohesiveEdges(const Multimesh& mesh, double relative_tolerance = 1e-9);

}  // namespace inbetween::solver
