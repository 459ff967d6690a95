// A compatible mesh by overlay, for when a mesh cannot be mapped into a drawing without folding.
//
// The mesh (one component bounded by one loop: a topological disk; OverlayOntoDomain below cuts
// a mesh with holes open into one first) is embedded into a convex
// polygon by Tutte's method (map_to_boundary.h), its boundary vertices on a circle. The new
// drawing's boundary polygon, through the same boundary vertices, is triangulated without
// Steiner points (a constrained Delaunay triangulation: every interior edge a chord between two
// boundary vertices); placed on the same circle, those chords cut the convex polygon into the
// same triangles, convex. Overlaying the two triangulations there gives a common refinement: each
// cell is a triangle of the mesh cut by the chords that cross it, convex, and lies inside one
// triangle of each, so the affine map of the mesh's triangle carries it into every drawing
// already mapped and the affine map of the chord triangle carries it into the new drawing, both
// orientation-preserving. The cells are fanned into triangles; the new vertices are where mesh
// edges cross chords. Every decision is combinatorial or an exact orientation test
// (cgal_predicates.h): a crossing's side of another chord is that chord's side of the other
// (chords of a triangulation do not cross), so the refinement is consistent even where the
// rounded crossing points are not. A result with a non-positive triangle in some drawing (a cell
// too thin for doubles) is retried with the boundary spaced differently on the circle.
//
// Chords passing close to mesh vertices cut thin pieces; every crossing whose merge into a
// neighbour leaves the thinnest triangle around it no thinner in any drawing is merged away
// (collapse_vertices.h), which removes most of them. What remains maps injectively into every
// drawing and may still have thin triangles: comesh optimization is the rest of the cleanup.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct OverlayResult {
  // Triangles over the input's vertices (same indices) followed by the new ones.
  std::vector<Triangle> triangles;
  // The input shapes extended to every vertex, then the new drawing's positions (last).
  std::vector<Points> shapes;
  int added_vertices = 0;  // crossings of mesh edges with chords (those not merged away)
};

// `triangles` is a mesh whose vertices 0..n-1 are placed in every shape of `shapes` (>= 1, each
// with every triangle positive); `boundary` is its only boundary loop in order, interior on the
// left; `target_boundary[k]` is where boundary[k] lies in the new drawing, a simple polygon of
// positive area with distinct points. shapes[0] gives the Tutte weights.
// Errors: INVALID_ARGUMENT (sizes, or a target that is not a simple positive polygon),
// FAILED_PRECONDITION (no placement on the circle gave a valid overlay), RESOURCE_EXHAUSTED (the
// result, after the merges, needs more than max_vertices vertices in all, or the refinement
// before them 4 times as many (at most 2,000,000); <= 0: no bound), CANCELLED.
absl::StatusOr<OverlayResult> OverlayOntoPolygon(const std::vector<Triangle>& triangles,
                                                 const std::vector<Points>& shapes,
                                                 const std::vector<int>& boundary,
                                                 const Points& target_boundary,
                                                 const CancelToken* cancel = nullptr,
                                                 int max_vertices = 0);

// The same for a mesh bounded by several loops (loops[0] and the others, e.g. an outline and
// its holes; each in order with the interior on its left), target_loops[l][k] being where
// loops[l][k] lies in the new drawing; points may repeat there (a closed cut walked both ways).
// The mesh is first cut open into a disk along paths of its edges through interior vertices
// that join every loop to loop 0, each between two vertices whose points in the new drawing
// an edge of that drawing's constrained Delaunay triangulation joins (a straight segment inside
// it, where the path's inner vertices are placed by arc length); the copies the cut makes are
// glued back in the result, whose vertices are the input's, then the new ones. One loop with
// distinct points is OverlayOntoPolygon. FAILED_PRECONDITION also when no such cut is found.
absl::StatusOr<OverlayResult> OverlayOntoDomain(const std::vector<Triangle>& triangles,
                                                const std::vector<Points>& shapes,
                                                const std::vector<std::vector<int>>& loops,
                                                const std::vector<Points>& target_loops,
                                                const CancelToken* cancel = nullptr,
                                                int max_vertices = 0);

}  // namespace inbetween::solver
