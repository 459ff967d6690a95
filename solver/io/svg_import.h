// SVG in: a drawing is layers of paint (fills and strokes, in paint order). Every painted
// element is kept as an art layer (Drawing::art); the drawing's outlines are the boundary of the
// union of all paint (solver/io/paint_union.h), cleaned of hairline gaps and specks.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct SvgImportOptions {
  double tolerance = 0.05;  // max distance (user units) between a curve and its flattening
  // Most points a document may produce: the points written in its path data and the points of
  // its flattened curves each count against it (a few bytes of huge arcs with a tiny tolerance
  // would flatten to millions of points). Above it: RESOURCE_EXHAUSTED, before the work is done.
  int max_points = 1'000'000;
  // Gaps in the paint narrower than this fraction of the paint's bounding-box diagonal are closed
  // (a morphological closing: grow by half of it, shrink back; corners are kept by miter joins).
  // 0 closes nothing.
  double gap_tolerance = 0.002;
  // Islands of paint and holes in it smaller than this fraction of the paint's bounding-box area
  // are dropped (specks, pinholes). 0 drops nothing.
  double min_area_fraction = 1e-4;
  // Most painted layers (elements with visible paint) a document may hold; above it:
  // RESOURCE_EXHAUSTED.
  int max_layers = 100'000;
};

// Where the outlines came from.
enum class SilhouetteSource {
  // The one-colour convention: filled elements that neither overlap nor touch (holes as nested
  // subpaths of one element); the outlines are the elements' own, exactly as written.
  kElements,
  kUnion,         // the union of all paint, cleaned
  kOutlineClass,  // the union of the class="outline" elements, cleaned
};

// What cleaning the union did (each count is of loops: outer outlines or holes).
struct PaintCleaning {
  int gaps_closed = 0;      // separate pieces of paint joined by closing hairline gaps
  int slits_closed = 0;     // holes narrower than the gap tolerance filled
  int islands_dropped = 0;  // pieces of paint below the area fraction
  int holes_dropped = 0;    // holes below the area fraction
  double gap_width = 0;     // the gap tolerance in user units
  double min_area = 0;      // the area threshold in square user units
};

// What the import saw besides the geometry (for renderers that want the drawing's look).
struct SvgImportInfo {
  // The fill colour 0xRRGGBB of the filled element whose outline encloses the largest area, when
  // the document gives it as a plain colour (fill attribute or style, possibly inherited);
  // nullopt when that element is filled by SVG's initial black, currentColor or a paint server.
  std::optional<uint32_t> fill_rgb;
  SilhouetteSource source = SilhouetteSource::kElements;
  PaintCleaning cleaning;
  // What was not imported or was approximated, each naming the element ("<text id="t"> (line 4):
  // text is not imported; convert it to paths"). Gradients arrive as the mean of their stops.
  std::vector<std::string> warnings;
};

// Parses an SVG document (text) and returns its outlines, outer ones positive, holes negative
// (see types.h), and its art layers (Drawing::art). Paint is a fill that is not "none" or a
// stroke of positive width, on an element that is displayed, visible and not fully transparent.
// Errors are INVALID_ARGUMENT naming the element and the reason; RESOURCE_EXHAUSTED above
// options.max_points or when <use> expansion would exceed 100000 elements. `info` (optional)
// receives what else the import saw.
absl::StatusOr<Drawing> ImportSvg(std::string_view svg_text, const SvgImportOptions& options = {},
                                  SvgImportInfo* info = nullptr);

}  // namespace inbetween::solver
