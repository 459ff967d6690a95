// Comesh optimization, outer loop: one pass of topology operations applied identically to every
// shape of a multimesh (DESIGN "Comesh optimization", S-Tables 1-4 "Outer"): edge flips, collapses
// of short interior edges, splits of long edges (interior, and boundary edges along the
// boundary). Each operation is accepted only if
//   - every new triangle is positive in EVERY shape, with area at least min_area_ratio times
//     that shape's mean triangle area (no slivers), and
//   - the comesh objective (comesh_objective.h) does not increase: flips and splits must lower
//     it, collapses must not raise it. The objective is evaluated as a mean quality for the
//     current triangle count T, E(T) = (1 - w) (T / T0) O + w M, with O, M the sums of the
//     per-triangle ODT and MIPS terms normalized for the pass's starting count T0, so that
//     removing or adding triangles is compared fairly.
// Collapses remove interior vertices and, along a boundary edge, boundary vertices that lie on a
// straight stretch of the boundary in every shape (TopologyOptions::boundary_collapses), or merge
// a corner of some shapes with a boundary neighbour that is a corner of the others (corner
// swaps); no shape loses a corner point, and cohesive-edge vertices, correspondence marks
// (Multimesh::pinned) and vertices listed in Multimesh::boundary but inside the mesh are never
// removed (a boundary endpoint keeps its place,
// shape by shape; two interior endpoints merge at the better of the midpoint and the kept
// vertex's position);
// the link condition keeps the mesh a manifold. A vertex touched by a collapse or split is not
// used by another one in the same pass, so each pass changes the mesh locally; the optimizer
// alternates passes with inner runs. The result is renumbered compactly (vertex order kept);
// Multimesh::boundary and boundary_loops (removed vertices dropped) and cohesive_edges are
// remapped; cohesive_closed is kept.
#pragma once

#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/comesh/comesh_outline.h"
#include "solver/core/cancel.h"
#include "solver/mesh/multimesh.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {

struct TopologyOptions {
  bool flips = true;
  bool collapses = true;
  bool splits = true;
  // Collapses may also remove a boundary vertex that lies strictly inside the straight segment
  // of its two boundary neighbours in every shape (a slider of the optimizer; never a corner, a
  // cohesive-edge vertex or a vertex of a non-manifold edge), merging it into a neighbour along
  // a boundary edge: every shape's domain and boundary polyline stay the same point set.
  bool boundary_collapses = true;
  // With boundary_collapses, a boundary edge (a, b) whose endpoints are each a corner only where
  // the other is straight may collapse too (a "corner swap"): the merged vertex keeps, in each
  // shape, the place of the endpoint that is a corner there. So a corner of one shape moves onto
  // a corner of another (square -> hexagon: 90 degrees onto 120 instead of onto 180), which the
  // optimizer's sliders, stopped at every corner, cannot do. Tried whatever the edge's length;
  // the objective decides as for every collapse.
  bool corner_swaps = true;
  // Splits may also take a boundary edge (a new slider at its midpoint, or with the optimizer's
  // outlines at the middle of its arc of the outline, see ImproveTopology), except next to a
  // cohesive-edge vertex or a correspondence mark.
  bool boundary_splits = true;
  // An interior edge is a collapse candidate when its length is below collapse_ratio times the
  // mean edge length in EVERY shape, a split candidate when above split_ratio times it in SOME
  // shape; the objective decides (see above).
  double collapse_ratio = 0.8;
  double split_ratio = 2.0;
  double min_area_ratio = 1e-2;  // new triangles: area >= this * mean triangle area, every shape
  // Flip sweeps per pass (until one accepts none): the first over every interior edge, each
  // later one (and the one after the collapses and splits) over the edges at the vertices that
  // changed since the sweep before.
  int flip_sweeps = 3;
};

struct TopologyReport {
  int flips = 0;
  int collapses = 0;
  int corner_swaps = 0;  // of the collapses, those that were corner swaps
  int splits = 0;
  double objective_before = 0.0;  // E of the input (for its own triangle count)
  double objective_after = 0.0;   // E of the output (for its own triangle count)
};

// Every edge (a, b), a < b, of the triangles t with alive[t] != 0, with the number of those
// triangles using it (1 = boundary, 2 = interior), in increasing (a, b) order. One sort of 3T
// pairs: the topology pass and the optimizer list edges often.
std::vector<std::pair<std::pair<int, int>, int>> EdgeUses(const std::vector<Triangle>& triangles,
                                                          const std::vector<char>& alive);
// The same into *uses, polling `cancel` every 4096 triangles and vertices (~0.15 s at 311k
// vertices without polls); false (and *uses unspecified) if it was set.
bool EdgeUses(const std::vector<Triangle>& triangles, const std::vector<char>& alive,
              const CancelToken* cancel, std::vector<std::pair<std::pair<int, int>, int>>* uses);

// TriangleQuality (4 sqrt(3) A / sum of squared edge lengths) is validate.h's.
// The smallest TriangleQuality over every triangle of every shape (1 without triangles).
double WorstQuality(const Multimesh& mesh);

// True if v lies strictly inside segment ab: strictly between a and b, and the polyline a-v-b
// turns at v by an angle whose sine is at most 1e-9 (the outlines' straightness tolerance too).
// The optimizer's slider test and the topology pass's boundary one.
bool StrictlyInsideSegment(const Point& a, const Point& b, const Point& v);

// One topology pass. `mesh` must be valid (positive triangles in every shape). The returned
// multimesh is valid too and has objective_after <= objective_before. CANCELLED (and no mesh) if
// `cancel` is set during the pass (polled before every candidate operation and every 4096 items
// of the edge and candidate lists). With `outlines` (one per shape; the optimizer's reference
// outlines, comesh_outline.h), a boundary split puts its new vertex on the outline in every shape
// (ShapeOutline::SplitPoint: the chord's midpoint on a straight stretch, the arc's middle across
// soft corners) and is not made where some shape has no such point; without, at the chord's
// midpoint.
absl::StatusOr<Multimesh> ImproveTopology(const Multimesh& mesh, double map_weight,
                                          const TopologyOptions& options,
                                          TopologyReport* report = nullptr,
                                          const CancelToken* cancel = nullptr,
                                          const std::vector<ShapeOutline>* outlines = nullptr);

// Sliver removal, the optimizer's last step: triangles whose quality (TriangleQuality) is below
// min_quality in some shape, worst first, each get one local operation applied identically to
// every shape: a needle collapses its short edge (also a boundary edge whose ends (nearly)
// coincide where one of them is a corner: within 1e-2 mean edge lengths; the merged vertex keeps
// the place that is a boundary point of `anchor_mesh` (the optimizer's input: so a drawn corner
// keeps its exact place, not the slider that slid onto it), else the one whose removal would
// change the boundary polygon more); a cap flips its long edge (interior) or, on the boundary,
// its corner moves onto that boundary edge and joins the boundary (a "snap": the triangle
// disappears, every shape's domain is unchanged; with `outlines`, only onto a point of every
// shape's outline); else the corner collapses into an end of the long edge. Each must keep every
// changed triangle positive (min_area_ratio of the mean area, as in ImproveTopology) and raise the
// worst quality of the triangles it changes; the objective may rise. Up to kSliverSweeps sweeps,
// until one changes nothing. Inner runs can make such slivers: two boundary sliders that meet, an
// interior vertex pressed onto a boundary edge, with the same shape in every drawing, so the map
// term (a ratio between shapes) does not resist, and the ODT term barely does.
struct SliverReport {
  int slivers_before = 0;  // triangles below min_quality
  int slivers_after = 0;
  int operations = 0;  // accepted operations
  int snaps = 0;       // of them, corners moved onto the boundary
  double worst_quality_before = 0.0;
  double worst_quality_after = 0.0;
};
inline constexpr int kSliverSweeps = 8;
absl::StatusOr<Multimesh> RemoveSlivers(const Multimesh& mesh, double map_weight,
                                        double min_quality, SliverReport* report = nullptr,
                                        const CancelToken* cancel = nullptr,
                                        const std::vector<ShapeOutline>* outlines = nullptr,
                                        const Multimesh* anchor_mesh = nullptr);

}  // namespace inbetween::solver
