// The region a drawing's paint covers, as outlines: fills under their fill-rule, strokes as the
// area they cover (width, caps, joins, dashes), all united, then cleaned of hairline gaps and
// specks. Polygon booleans and offsetting are Clipper's (libpolyclipping, integer coordinates:
// the paint's extent is quantized to 2^29 steps, below 1e-8 of the drawing's size).
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/art.h"
#include "solver/core/types.h"
#include "solver/io/svg_import.h"

namespace inbetween::solver {

struct PaintUnionOptions {
  double arc_tolerance = 0.05;  // max distance between a round cap or join and its polygon
  double gap_width = 0;         // user units: gaps narrower than this are closed (0: none)
  double min_area = 0;          // square user units: islands and holes below it dropped (0: none)
};

struct PaintRegion {
  std::vector<Outline> outlines;  // outer outlines positive, holes negative (types.h)
  double raw_area = 0;            // painted area before cleaning
  double layers_area = 0;         // the sum of each layer's own painted area (overlaps counted
                                  // once per layer: equals raw_area when no two layers overlap)
  // The paint is nowhere wider than the gap width (it would vanish as hairlines). Reported, not
  // refused here: a one-colour drawing keeps its own outlines whatever their width.
  bool hairline = false;
  PaintCleaning cleaning;  // counts only; gap_width and min_area as given
};

// The union of the layers' paint. A layer contributes its fill (if any) and its stroke (if any);
// its opacity does not matter (faint paint is still paint). Errors: INVALID_ARGUMENT when
// nothing is painted or the paint covers no area. Every piece may be cleaned away (no outlines
// left): the caller says why.
absl::StatusOr<PaintRegion> UnionOfPaint(const std::vector<const ArtLayer*>& layers,
                                         const PaintUnionOptions& options);

// The open pieces a dash pattern leaves of a polyline (`dashes` alternate on and off lengths,
// an even count with a positive sum; `offset` is SVG's stroke-dashoffset). A dash of length zero
// is a single point (drawn by round and square caps).
std::vector<Points> DashPolyline(const Points& points, bool closed,
                                 const std::vector<double>& dashes, double offset);

}  // namespace inbetween::solver
