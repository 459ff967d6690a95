// A request's drawing (SVG text or explicit polylines) -> validated outline elements and the
// solver drawing made of them.
#pragma once

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inbetween/v1/inbetween.pb.h"
#include "solver/core/types.h"

namespace inbetween::server {

inline constexpr double kDefaultFlattenTolerance = 0.05;
inline constexpr double kMaxCoordinate = 1e9;
inline constexpr int kMaxPointsPerDrawing = 1'000'000;
inline constexpr size_t kMaxNameBytes = 256;

struct ImportedDrawing {
  solver::Drawing parsed;
  // OUTLINE elements with ids 1..n, in the order of parsed.outlines.
  google::protobuf::RepeatedPtrField<inbetween::v1::TopologyElement> elements;
  // Read from the outlines' orientation: components = outer (positive) outlines, holes =
  // negative ones. Graph flow (S-Alg.1) will replace this once cuts and openings exist.
  inbetween::v1::EquivalenceClass equivalence_class;
};

// Imports drawing.svg (with `flatten_tolerance`, 0 = default) or drawing.polylines and checks
// the name, key_time and every outline (>= 3 finite points, |coordinate| <= 1e9, non-zero area,
// not self-intersecting, at least one positive outline). Errors name `field` (e.g. "drawing") and
// the element index: INVALID_ARGUMENT for bad input, UNIMPLEMENTED for cuts and openings (not
// supported yet), RESOURCE_EXHAUSTED above kMaxPointsPerDrawing.
absl::StatusOr<ImportedDrawing> ImportDrawing(const inbetween::v1::Drawing& drawing,
                                              double flatten_tolerance, absl::string_view field);

// Same checks for a drawing whose elements are already filled in (a stored or archived drawing).
absl::StatusOr<ImportedDrawing> ImportDrawingElements(const inbetween::v1::Drawing& drawing,
                                                      absl::string_view field);

}  // namespace inbetween::server
