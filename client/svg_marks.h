// Correspondence marks drawn in the SVGs (data-corr="N", docs/svg-convention.md) as project
// correspondences. The service stores drawings as outlines/cuts/openings and has no place for
// marks, so the CLI reads them on its side and sends them with SetCorrespondences, as
// BuildMultimesh would use Drawing::marks (ordered by mark id, each in every drawing or none).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/project_file.h"

namespace inbetween::client {

// One correspondence (a point per drawing) per mark id, ascending; empty when no drawing has
// marks. Errors (INVALID_ARGUMENT): an id missing from some drawing, or twice in one drawing.
// Drawings that do not import are skipped here (the upload reports them).
absl::StatusOr<std::vector<XYs>> SvgMarkCorrespondences(const std::vector<std::string>& svg_texts);

}  // namespace inbetween::client
