// A request's drawing (SVG text or explicit polylines) plus its cuts and openings -> validated
// topology elements, the solver drawing made of them and its boundaries (S-Alg.1 graph flow).
#pragma once

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inbetween/v1/inbetween.pb.h"
#include "solver/core/types.h"
#include "solver/geometry/graph_flow.h"

namespace inbetween::server {

inline constexpr double kDefaultFlattenTolerance = 0.05;
// Upper bound of PutDrawingRequest.gap_tolerance and .min_area_fraction.
inline constexpr double kMaxImportFraction = 0.1;
inline constexpr double kMaxCoordinate = 1e9;
inline constexpr int kMaxPointsPerDrawing = 1'000'000;
inline constexpr size_t kMaxNameBytes = 256;
// Consecutive points of an element closer than this times its bounding-box diagonal are merged
// before the checks (docs/project-file.md, "Geometry clean-up").
inline constexpr double kMergeRelativeTolerance = 1e-9;

using TopologyElements = google::protobuf::RepeatedPtrField<inbetween::v1::TopologyElement>;

// How an SVG source is imported, as PutDrawingRequest gives it: 0 = the default, each checked
// by ImportDrawing (INVALID_ARGUMENT naming the request field).
struct DrawingImportOptions {
  double flatten_tolerance = 0;  // (0, 1e6]; 0 = kDefaultFlattenTolerance
  // (0, kMaxImportFraction]; 0 = SvgImportOptions' default; negative = off (0 for ImportSvg).
  double gap_tolerance = 0;
  double min_area_fraction = 0;  // as gap_tolerance
};

struct ImportedDrawing {
  // The solver drawing: OUTLINE elements as outlines, CUT as cuts, OPENING as openings, each in
  // element order (SolverDrawing() of the elements), with the drawing's marks and art.
  solver::Drawing parsed;
  // Every element with its id (>= 1, unique within the drawing).
  TopologyElements elements;
  // Closed boundaries, cohesive twins and the equivalence class from BuildBoundaries.
  solver::BoundaryGraph boundaries;
  inbetween::v1::EquivalenceClass equivalence_class;
  // What the import did (Drawing.import_report): ImportSvg's report for an SVG source, source
  // ELEMENTS and no art for polylines, the drawing's own for ImportDrawingElements.
  inbetween::v1::ImportReport import_report;
};

// Imports drawing.svg (with `options`) or drawing.polylines, appends the `topology` elements
// (CUT or OPENING, id 0; named `topology_field`), numbers new elements and checks everything:
// name, key_time, outlines (>= 3 finite points, |coordinate| <= 1e9, non-zero area, not
// self-intersecting, at least one positive outline), cuts and openings (>= 2 finite points), the
// art (finite points, |coordinate| <= 1e9, paint in range) and the graph flow of the whole
// drawing. Drawing.art and .import_report of the request are ignored (output only).
// `drawing_number` (1-based) names the drawing in the solver's messages. Errors name `field` and
// the element: INVALID_ARGUMENT for bad input, RESOURCE_EXHAUSTED above max_points.
absl::StatusOr<ImportedDrawing> ImportDrawing(const inbetween::v1::Drawing& drawing,
                                              const DrawingImportOptions& options,
                                              absl::string_view field, int drawing_number,
                                              const TopologyElements& topology = {},
                                              absl::string_view topology_field = "topology",
                                              int max_points = kMaxPointsPerDrawing);

// Same checks for a drawing whose elements are already filled in (a stored, archived or edited
// drawing); its art and import report are kept (the art checked as above). Ids are kept;
// elements with id 0 get fresh ones; repeated ids are INVALID_ARGUMENT.
absl::StatusOr<ImportedDrawing> ImportDrawingElements(const inbetween::v1::Drawing& drawing,
                                                      absl::string_view field, int drawing_number,
                                                      int max_points = kMaxPointsPerDrawing);

// Writes an import into the drawing to store: its elements, marks, art and import report (each
// replacing what the drawing had).
void StoreImport(const ImportedDrawing& imported, inbetween::v1::Drawing* drawing);

// A drawing's correspondence marks (Drawing.marks) for the solver, and back.
std::vector<solver::CorrespondenceMark> MarksOf(const inbetween::v1::Drawing& drawing);
void SetMarks(const std::vector<solver::CorrespondenceMark>& marks, inbetween::v1::Drawing* drawing);

// The equivalence class as the API reports it.
inbetween::v1::EquivalenceClass ToProto(const solver::EquivalenceClass& equivalence);

}  // namespace inbetween::server
