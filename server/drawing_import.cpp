// Drawing validation and import; the SVG parsing itself is solver::ImportSvg.
#include "server/drawing_import.h"

#include <cmath>
#include <optional>
#include <string>

#include "absl/strings/str_cat.h"
#include "solver/geometry/polygon.h"
#include "solver/io/svg_import.h"

namespace inbetween::server {
namespace {

using inbetween::v1::ElementKind;
using inbetween::v1::TopologyElement;

absl::Status CheckOutline(const solver::Points& points, const std::string& where) {
  if (points.size() < 3) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, " has ", points.size(), " points, an outline needs at least 3"));
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const solver::Point& p = points[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || std::abs(p.x()) > kMaxCoordinate ||
        std::abs(p.y()) > kMaxCoordinate) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, " point ", i, " (", p.x(), ", ", p.y(),
                       ") is not finite or exceeds |coordinate| <= 1e9"));
    }
  }
  const double area = solver::PolygonSignedArea(points);
  if (!(std::abs(area) > 0.0) || !std::isfinite(area)) {
    return absl::InvalidArgumentError(absl::StrCat(where, " has zero area"));
  }
  if (std::optional<solver::SelfIntersection> x = solver::FindSelfIntersection(points)) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, " crosses itself: segments ", x->segment_a, " and ", x->segment_b,
                     " meet at (", x->location.x(), ", ", x->location.y(), ")"));
  }
  return absl::OkStatus();
}

// Shared tail of both entry points: checks the outlines, numbers them and classifies them.
absl::StatusOr<ImportedDrawing> FromOutlines(solver::Drawing parsed, absl::string_view field,
                                             absl::string_view element_field) {
  ImportedDrawing out;
  size_t total_points = 0;
  for (size_t i = 0; i < parsed.outlines.size(); ++i) {
    const solver::Points& points = parsed.outlines[i].points;
    total_points += points.size();
    if (total_points > static_cast<size_t>(kMaxPointsPerDrawing)) {
      return absl::ResourceExhaustedError(absl::StrCat(
          field, " has more than ", kMaxPointsPerDrawing, " points (limit per drawing)"));
    }
    if (absl::Status s = CheckOutline(points, absl::StrCat(field, ".", element_field, "[", i, "]"));
        !s.ok()) {
      return s;
    }
    TopologyElement* element = out.elements.Add();
    element->set_id(static_cast<uint32_t>(i + 1));
    element->set_kind(inbetween::v1::ELEMENT_KIND_OUTLINE);
    for (const solver::Point& p : points) {
      inbetween::v1::Point* q = element->mutable_polyline()->add_points();
      q->set_x(p.x());
      q->set_y(p.y());
    }
    if (solver::PolygonSignedArea(points) > 0) {
      out.equivalence_class.set_components(out.equivalence_class.components() + 1);
    } else {
      out.equivalence_class.set_holes(out.equivalence_class.holes() + 1);
    }
  }
  if (out.equivalence_class.components() == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        field,
        " has no outer outline (an outline with positive signed area, i.e. clockwise on "
        "screen with y down)"));
  }
  out.parsed = std::move(parsed);
  return out;
}

absl::Status CheckDrawingFields(const inbetween::v1::Drawing& drawing, absl::string_view field) {
  if (drawing.name().size() > kMaxNameBytes) {
    return absl::InvalidArgumentError(absl::StrCat(field, ".name is ", drawing.name().size(),
                                                   " bytes, the limit is ", kMaxNameBytes));
  }
  if (drawing.has_key_time() &&
      !(std::isfinite(drawing.key_time()) && drawing.key_time() >= 0 && drawing.key_time() <= 1)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".key_time = ", drawing.key_time(), " is not in [0, 1]"));
  }
  return absl::OkStatus();
}

// Converts explicit elements (request polylines or stored elements) to outlines.
absl::StatusOr<solver::Drawing> OutlinesFromElements(
    const google::protobuf::RepeatedPtrField<TopologyElement>& elements, absl::string_view field) {
  solver::Drawing parsed;
  for (int i = 0; i < elements.size(); ++i) {
    const TopologyElement& element = elements[i];
    const std::string where = absl::StrCat(field, "[", i, "]");
    switch (element.kind()) {
      case inbetween::v1::ELEMENT_KIND_OUTLINE:
        break;
      case inbetween::v1::ELEMENT_KIND_CUT:
      case inbetween::v1::ELEMENT_KIND_OPENING:
        return absl::UnimplementedError(
            absl::StrCat(where, ".kind = ", inbetween::v1::ElementKind_Name(element.kind()),
                         ": cuts and openings are not supported yet in this server version"));
      default:
        return absl::InvalidArgumentError(
            absl::StrCat(where, ".kind must be ELEMENT_KIND_OUTLINE"));
    }
    solver::Outline& outline = parsed.outlines.emplace_back();
    outline.points.reserve(element.polyline().points_size());
    for (const inbetween::v1::Point& p : element.polyline().points()) {
      outline.points.emplace_back(p.x(), p.y());
    }
  }
  return parsed;
}

}  // namespace

absl::StatusOr<ImportedDrawing> ImportDrawing(const inbetween::v1::Drawing& drawing,
                                              double flatten_tolerance, absl::string_view field) {
  if (absl::Status s = CheckDrawingFields(drawing, field); !s.ok()) return s;
  if (flatten_tolerance == 0) flatten_tolerance = kDefaultFlattenTolerance;
  if (!(std::isfinite(flatten_tolerance) && flatten_tolerance > 0 && flatten_tolerance <= 1e6)) {
    return absl::InvalidArgumentError(
        absl::StrCat("flatten_tolerance = ", flatten_tolerance, " is not in (0, 1e6]"));
  }
  switch (drawing.source_case()) {
    case inbetween::v1::Drawing::kSvg: {
      if (drawing.svg().empty()) {
        return absl::InvalidArgumentError(absl::StrCat(field, ".svg is empty"));
      }
      solver::SvgImportOptions options;
      options.tolerance = flatten_tolerance;
      absl::StatusOr<solver::Drawing> parsed = solver::ImportSvg(drawing.svg(), options);
      if (!parsed.ok()) {
        return absl::Status(parsed.status().code(),
                            absl::StrCat(field, ".svg: ", parsed.status().message()));
      }
      if (parsed->outlines.empty()) {
        return absl::InvalidArgumentError(absl::StrCat(field, ".svg has no filled shapes"));
      }
      return FromOutlines(*std::move(parsed), field, "svg outline");
    }
    case inbetween::v1::Drawing::kPolylines: {
      const std::string elements_field = absl::StrCat(field, ".polylines.elements");
      absl::StatusOr<solver::Drawing> parsed =
          OutlinesFromElements(drawing.polylines().elements(), elements_field);
      if (!parsed.ok()) return parsed.status();
      return FromOutlines(*std::move(parsed), field, "polylines.elements");
    }
    default:
      return absl::InvalidArgumentError(
          absl::StrCat(field, " has no source: set ", field, ".svg or ", field, ".polylines"));
  }
}

absl::StatusOr<ImportedDrawing> ImportDrawingElements(const inbetween::v1::Drawing& drawing,
                                                      absl::string_view field) {
  if (absl::Status s = CheckDrawingFields(drawing, field); !s.ok()) return s;
  absl::StatusOr<solver::Drawing> parsed =
      OutlinesFromElements(drawing.elements(), absl::StrCat(field, ".elements"));
  if (!parsed.ok()) return parsed.status();
  return FromOutlines(*std::move(parsed), field, "elements");
}

}  // namespace inbetween::server
