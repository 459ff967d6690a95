// SVG in: filled shapes of an SVG document become the outlines of one Drawing.
#pragma once

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

// Parses an SVG document (text) and returns its filled outlines, outer ones positive, holes
// negative (see types.h). Errors are INVALID_ARGUMENT naming the element and the reason;
// RESOURCE_EXHAUSTED above options.max_points or when <use> expansion would exceed 100000
// elements.
absl::StatusOr<Drawing> ImportSvg(std::string_view svg_text, const SvgImportOptions& options = {});

}  // namespace inbetween::solver
