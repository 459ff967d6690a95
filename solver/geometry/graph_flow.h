// S-Alg.1: directed graph flow. Outlines (1-directed), cuts and openings (bi-directed) form a
// planar straight-line graph; walking its directed cycles rebuilds the closed S^1 boundaries,
// turns every cut/opening segment into a cohesive edge pair and gives the drawing's equivalence
// class (components and holes, S-Sec.1 and S-Fig.1).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"

namespace inbetween::solver {

// ---- The bare algorithm on a given graph (S-Alg.1) ----

struct GraphEdge {
  int from = 0;
  int to = 0;
  bool bidirected = false;  // cut/opening segment: may be walked both ways
};

// One directed cycle: the half-edges walked, in order. Half-edge 2*e walks edge e from->to,
// 2*e+1 walks it to->from (bi-directed edges only).
struct FlowCycle {
  std::vector<int> half_edges;
  std::vector<int> nodes;  // nodes[k] = start node of half_edges[k]
};

struct GraphFlowResult {
  std::vector<FlowCycle> cycles;
  std::vector<int> visits;  // per edge: 1 for 1-directed, 2 for bi-directed after a full flow
};

// Walks directed cycles until every 1-directed edge is visited once and every bi-directed edge
// twice (once each way). At a node the next edge is the outgoing one clockwise-closest to the
// incoming edge (measured from the reversed incoming direction; clockwise = negative
// orientation in the drawing's coordinates), which keeps the drawing on the left of every
// boundary. The graph must be planar with no repeated or overlapping edges. Errors
// (INVALID_ARGUMENT, naming the node's location): a node where the flow cannot go on (dangling
// 1-directed edge) or would reuse an edge before closing its cycle.
absl::StatusOr<GraphFlowResult> DirectedGraphFlow(const Points& nodes,
                                                  const std::vector<GraphEdge>& edges);

// ---- Drawings -> boundaries ----

// An equivalence class of S-Fig.1: disjoint union of `components` disks, with holes.
struct EquivalenceClass {
  int components = 0;
  int holes = 0;
  std::vector<int> holes_per_component;  // sorted descending
  bool operator==(const EquivalenceClass& o) const {
    return components == o.components && holes_per_component == o.holes_per_component;
  }
  // "1 component, 0 holes", "2 components (holes 1+0)".
  std::string ToString() const;
};

// A closed boundary: the drawing lies on its left (outer loops positive, holes non-positive
// signed area; a slit hole has zero area).
struct BoundaryLoop {
  Points points;
  // twin[k] for edge k (points[k] -> points[k+1]): {loop, edge} of the collocated edge walked
  // the other way (the other side of a cut or opening), or {-1, -1} for an outline edge.
  std::vector<std::pair<int, int>> twin;
  bool outer = true;
  int component = 0;  // index of the component (its outer loop is the component's loop)
};

struct BoundaryGraph {
  std::vector<BoundaryLoop> loops;  // outer loops first (one per component), then holes
  EquivalenceClass equivalence;
  int one_directed_edges = 0;  // edges of the graph after splitting at intersections
  int bi_directed_edges = 0;
};

struct BoundaryOptions {
  // Cut/opening end points closer than this (relative to the drawing's bounding-box diagonal)
  // to an outline are snapped onto it.
  double snap_relative = 1e-6;
  // Candidate segment pairs (overlapping in x) the intersection sweep may examine before it
  // gives up with RESOURCE_EXHAUSTED: the sweep is O(n^2) on combs of long overlapping segments,
  // so this bounds the time per drawing (about a second); ordinary drawings of a million points
  // need a few million.
  int64_t max_pair_checks = 50'000'000;
};

// Builds the planar straight-line graph of `drawing` (outlines oriented by nesting, cut and
// opening polylines clipped to the shape: parts beyond the outline at either end are dropped),
// splits segments at their intersections (exact predicates), runs DirectedGraphFlow and
// classifies the loops. `drawing_number` (1-based) names the drawing in messages. Errors
// (INVALID_ARGUMENT with the location): self-intersecting or crossing outlines, a cut that
// leaves the shape and comes back, cuts overlapping each other or an outline, a flow that
// cannot close.
absl::StatusOr<BoundaryGraph> BuildBoundaries(const Drawing& drawing, int drawing_number,
                                              const BoundaryOptions& options = {});

}  // namespace inbetween::solver
