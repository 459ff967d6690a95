// SVG in: filled shapes of an SVG document become the outlines of one Drawing.
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct SvgImportOptions {
  double tolerance = 0.05;  // max distance (user units) between a curve and its flattening
};

// Parses an SVG document (text) and returns its filled outlines, outer ones positive, holes
// negative (see types.h). Errors are INVALID_ARGUMENT naming the element and the reason.
absl::StatusOr<Drawing> ImportSvg(std::string_view svg_text, const SvgImportOptions& options = {});

}  // namespace inbetween::solver
