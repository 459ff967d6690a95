// Vertex numbering along a Hilbert curve, for memory locality. The comesh optimizer and the
// inbetweening solver loop over triangles and gather their corners' positions; with the mesher's
// numbering (insertion order) a triangle's corners lie anywhere in memory (mean index distance
// along an edge ~ n / 4 on the S-Table 2 meshes), with a Hilbert numbering a few hundred.
// Measured on the 311k-vertex S-Table 2 row (one run each): Hessian set-up 20%, step bound 33%
// and topology passes 40% less time, 16% less in total (270 inner iterations against 260: the
// iteration counts move with the numbering); at 35k-73k the set-up and topology gains remain and
// the rest is within noise (docs/benchmarks.md, "Decisions and what they rest on").
#pragma once

#include <vector>

#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

// to[v] = the new index of vertex v: vertices sorted by their position's index on a Hilbert curve
// of order 16 over the points' bounding box, ties (same curve cell) by index. Deterministic, and
// the identity on points that are already in that order.
std::vector<int> HilbertOrder(const Points& points);

// Renumbers `mesh` so that its vertices follow HilbertOrder(mesh->shapes[0]) and its triangles
// are sorted (stably) by their smallest vertex; each triangle keeps its corners' cyclic order
// (orientation). Boundary, boundary loops and cohesive edges are renumbered with the vertices
// (their order kept; cohesive_closed indexes cohesive_edges and is unchanged). Idempotent.
void RenumberSpatially(Multimesh* mesh);

}  // namespace inbetween::solver
