// SVG in: filled shapes of an SVG document become the outlines of one Drawing.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "absl/status/statusor.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct SvgImportOptions {
  double tolerance = 0.05;  // max distance (user units) between a curve and its flattening
  // Most points a document may produce: the points written in its path data and the points of
  // its flattened curves each count against it (a few bytes of huge arcs with a tiny tolerance
  // would flatten to millions of points). Above it: RESOURCE_EXHAUSTED, before the work is done.
  int max_points = 1'000'000;
};

// What the import saw besides the geometry (for renderers that want the drawing's look).
struct SvgImportInfo {
  // The fill colour 0xRRGGBB of the filled element whose outline encloses the largest area, when
  // the document gives it as a plain colour (fill attribute or style, possibly inherited);
  // nullopt when that element is filled by SVG's initial black, currentColor or a paint server.
  std::optional<uint32_t> fill_rgb;
};

// Parses an SVG document (text) and returns its filled outlines, outer ones positive, holes
// negative (see types.h). Errors are INVALID_ARGUMENT naming the element and the reason;
// RESOURCE_EXHAUSTED above options.max_points or when <use> expansion would exceed 100000
// elements.
// `info` (optional) receives what else the import saw.
absl::StatusOr<Drawing> ImportSvg(std::string_view svg_text, const SvgImportOptions& options = {},
                                  SvgImportInfo* info = nullptr);

}  // namespace inbetween::solver
