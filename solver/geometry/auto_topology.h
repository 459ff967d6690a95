// Auto-topology: when key drawings fall into different equivalence classes (components, holes;
// S-Sec.1, S-Fig.1), propose the topology edits that bring them into one class, so an artist
// does not have to draw them by hand (`inbetween animate --auto-topology`). A drawing with fewer
// pieces than another is cut across its narrowest neck (the shortest straight chord inside it
// that leaves at least 10% of the area on each side); extra holes are joined to their
// component's outline by the shortest straight cut that stays inside the shape (a cut
// hole-to-outline turns an annulus into a disk). The cohesive edges of a cut keep it closed
// while the energy stays below tau.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"
#include "solver/geometry/graph_flow.h"

namespace inbetween::solver {

struct AutoTopologyOptions {
  // Vertex pairs (hole vertex, outline vertex) tried, shortest first, when no nearest-point
  // candidate gives a segment inside the shape (e.g. another hole sits in the way).
  int max_pair_candidates = 200000;
  // A cut that splits a piece must leave at least this share of its area on either side (so it
  // does not just shave off a sliver).
  double min_split_part = 0.1;
};

struct AutoTopologyResult {
  EquivalenceClass target;                // the class every drawing has after the edits
  std::vector<std::vector<Points>> cuts;  // per drawing (input order): proposed cuts, 2 points
  // One line per proposal, e.g. "drawing 2: cut from hole 1 to the outline, length 12.5".
  std::vector<std::string> notes;
};

// Proposes cuts so that every drawing (with its own cuts and openings already applied) has the
// same equivalence class: first every drawing is split (largest piece first) until it has as many
// components as the drawing with the most; then, per component rank (components ordered by hole
// count), each drawing keeps as many holes as the drawing with fewest there; the smallest extra
// holes are cut. Each cut is a straight segment from a hole vertex or edge midpoint to the nearest
// point of the component's outline (or the reverse), the shortest one that crosses no boundary and
// no earlier proposed cut, drawn overhanging both ends slightly (1%) as cuts should (the builder
// clips it). The result is checked by rebuilding the boundaries. Errors: INVALID_ARGUMENT from
// BuildBoundaries (naming the drawing), FAILED_PRECONDITION when no straight cut does the job
// (the message says what to draw by hand).
absl::StatusOr<AutoTopologyResult> ProposeTopology(const std::vector<Drawing>& drawings,
                                                   const AutoTopologyOptions& options = {});

}  // namespace inbetween::solver
