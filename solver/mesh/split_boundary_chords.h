// Splits every interior edge whose two endpoints are boundary vertices ("chords").
#pragma once

#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// A chord can become degenerate when the mesh is mapped into a shape whose boundary is straight
// where shape 1's is not (a convex Tutte embedding flattens it onto one side). Each chord is
// split at its midpoint by a new interior vertex (appended to `vertices`), which also leaves no
// triangle with three boundary vertices. `is_boundary` is indexed by vertex and is extended.
// Returns the number of chords split.
int SplitBoundaryChords(Points* vertices, std::vector<Triangle>* triangles,
                        std::vector<bool>* is_boundary);

// The same for edges with at least min_boundary_ends (1 or 2) ends on the boundary, the
// midpoints added to every shape in `shapes` (same sizes as is_boundary). SplitBoundaryChords is
// this with one shape and 2.
int SplitInteriorEdges(const std::vector<Points*>& shapes, std::vector<Triangle>* triangles,
                       std::vector<bool>* is_boundary, int min_boundary_ends);

}  // namespace inbetween::solver
