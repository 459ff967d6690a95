// Drawing validation and import; the SVG parsing is solver::ImportSvg and the boundaries are
// solver::BuildBoundaries (S-Alg.1), whose messages name the drawing and the location.
#include "server/drawing_import.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/proto_convert.h"
#include "solver/core/error_reason.h"
#include "solver/geometry/polygon.h"
#include "solver/io/svg_import.h"

namespace inbetween::server {
namespace {

namespace v1 = ::inbetween::v1;

absl::Status CheckPoints(const solver::Points& points, const std::string& where) {
  for (size_t i = 0; i < points.size(); ++i) {
    const solver::Point& p = points[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || std::abs(p.x()) > kMaxCoordinate ||
        std::abs(p.y()) > kMaxCoordinate) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, " point ", i, " (", p.x(), ", ", p.y(),
                       ") is not finite or exceeds |coordinate| <= 1e9"));
    }
  }
  return absl::OkStatus();
}

absl::Status CheckOutline(const solver::Points& points, const std::string& where) {
  if (points.size() < 3) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, " has ", points.size(), " points, an outline needs at least 3"));
  }
  if (absl::Status s = CheckPoints(points, where); !s.ok()) return s;
  const double area = solver::PolygonSignedArea(points);
  if (!(std::abs(area) > 0.0) || !std::isfinite(area)) {
    return absl::InvalidArgumentError(absl::StrCat(where, " has zero area"));
  }
  bool gave_up = false;
  std::optional<solver::SelfIntersection> x =
      solver::FindSelfIntersection(points, solver::BoundaryOptions().max_pair_checks, &gave_up);
  if (gave_up) {
    return absl::ResourceExhaustedError(absl::StrCat(
        where, " has too many long segments side by side to check for crossings (more than ",
        solver::BoundaryOptions().max_pair_checks, " candidate pairs); simplify it"));
  }
  if (x) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, " crosses itself: segments ", x->segment_a, " and ", x->segment_b,
                     " meet at (", x->location.x(), ", ", x->location.y(), ")"));
  }
  return absl::OkStatus();
}

absl::Status CheckOpenPolyline(const solver::Points& points, const std::string& where) {
  if (points.size() < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, " has ", points.size(), " points, a cut or opening needs at least 2"));
  }
  return CheckPoints(points, where);
}

// Near-duplicate cleaning (docs/project-file.md, "Geometry clean-up"): consecutive points closer
// than kMergeRelativeTolerance times the element's bounding-box diagonal are merged (the first
// is kept), and for a closed outline a last point repeating the first is dropped. What remains is
// checked as usual, so cleaning never hides a degenerate or crossing outline.
solver::Points MergeNearDuplicates(const solver::Points& points, bool closed) {
  if (points.size() < 2) return points;
  solver::Point lo = points[0], hi = points[0];
  for (const solver::Point& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double tolerance = kMergeRelativeTolerance * (hi - lo).norm();
  if (!std::isfinite(tolerance)) return points;  // CheckPoints reports the coordinate
  solver::Points out;
  out.reserve(points.size());
  for (const solver::Point& p : points) {
    if (out.empty() || (p - out.back()).norm() > tolerance) out.push_back(p);
  }
  while (closed && out.size() > 1 && (out.back() - out.front()).norm() <= tolerance) {
    out.pop_back();
  }
  return out;
}

// `field`[i], plus the element id for stored elements, e.g. "drawing 2.elements[2] (element 5)".
std::string ElementName(absl::string_view field, int i, const v1::TopologyElement& element,
                        bool with_id) {
  std::string name = absl::StrCat(field, "[", i, "]");
  if (with_id) absl::StrAppend(&name, " (element ", element.id(), ")");
  return name;
}

// Shared tail of every entry point: checks each element by kind, builds the solver drawing and
// runs the graph flow. `elements` have their final ids.
absl::StatusOr<ImportedDrawing> Analyze(TopologyElements elements, absl::string_view field,
                                        absl::string_view element_field, bool with_ids,
                                        int drawing_number, int max_points) {
  ImportedDrawing out;
  size_t total_points = 0;
  bool has_positive_outline = false;
  for (int i = 0; i < elements.size(); ++i) {
    const v1::TopologyElement& element = elements[i];
    std::string where = ElementName(element_field, i, element, with_ids);
    total_points += element.polyline().points_size();
    if (total_points > static_cast<size_t>(max_points)) {
      return absl::ResourceExhaustedError(
          absl::StrCat(field, " has more than ", max_points,
                       " points (limit per drawing, --max-drawing-points)"));
    }
    const bool closed = element.kind() == v1::ELEMENT_KIND_OUTLINE;
    solver::Points points = FromProto(element.polyline().points());
    if (absl::Status s = CheckPoints(points, where); !s.ok()) return s;  // before merging
    points = MergeNearDuplicates(points, closed);
    if (points.size() != static_cast<size_t>(element.polyline().points_size())) {
      absl::StrAppend(&where, " (", element.polyline().points_size(), " points, ", points.size(),
                      " after merging near-duplicates)");
      elements[i].mutable_polyline()->clear_points();  // stored cleaned
      ToProto(points, elements[i].mutable_polyline()->mutable_points());
    }
    switch (element.kind()) {
      case v1::ELEMENT_KIND_OUTLINE:
        if (absl::Status s = CheckOutline(points, where); !s.ok()) return s;
        has_positive_outline |= solver::PolygonSignedArea(points) > 0;
        out.parsed.outlines.push_back({std::move(points)});
        break;
      case v1::ELEMENT_KIND_CUT:
        if (absl::Status s = CheckOpenPolyline(points, where); !s.ok()) return s;
        out.parsed.cuts.push_back(std::move(points));
        break;
      case v1::ELEMENT_KIND_OPENING:
        if (absl::Status s = CheckOpenPolyline(points, where); !s.ok()) return s;
        out.parsed.openings.push_back(std::move(points));
        break;
      default:
        return absl::InvalidArgumentError(absl::StrCat(
            where, ".kind must be ELEMENT_KIND_OUTLINE, ELEMENT_KIND_CUT or ELEMENT_KIND_OPENING"));
    }
  }
  if (!has_positive_outline) {
    return absl::InvalidArgumentError(absl::StrCat(
        field,
        " has no outer outline (an outline with positive signed area, i.e. clockwise on "
        "screen with y down)"));
  }
  absl::StatusOr<solver::BoundaryGraph> boundaries =
      solver::BuildBoundaries(out.parsed, drawing_number);
  if (!boundaries.ok()) {
    // The solver names the drawing ("drawing 2, cut 1 ..."); add the field unless it says the same.
    const absl::string_view message = boundaries.status().message();
    if (absl::StartsWith(message, field)) return boundaries.status();
    return absl::Status(boundaries.status().code(), absl::StrCat(field, ": ", message));
  }
  out.boundaries = *std::move(boundaries);
  out.equivalence_class = ToProto(out.boundaries.equivalence);
  out.elements = std::move(elements);
  return out;
}

absl::Status CheckDrawingFields(const v1::Drawing& drawing, absl::string_view field) {
  if (drawing.name().size() > kMaxNameBytes) {
    return absl::InvalidArgumentError(absl::StrCat(field, ".name is ", drawing.name().size(),
                                                   " bytes, the limit is ", kMaxNameBytes));
  }
  for (int i = 0; i < drawing.marks_size(); ++i) {
    const v1::DrawingMark& mark = drawing.marks(i);
    if (!std::isfinite(mark.point().x()) || !std::isfinite(mark.point().y()) ||
        std::abs(mark.point().x()) > 1e9 || std::abs(mark.point().y()) > 1e9) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".marks[", i, "].point = (", mark.point().x(), ", ",
                       mark.point().y(), ") is not finite or beyond 1e9"));
    }
    if (mark.id() > static_cast<uint32_t>(std::numeric_limits<int>::max())) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".marks[", i, "].id = ", mark.id(), " is too large"));
    }
  }
  if (drawing.has_key_time() &&
      !(std::isfinite(drawing.key_time()) && drawing.key_time() >= 0 && drawing.key_time() <= 1)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".key_time = ", drawing.key_time(), " is not in [0, 1]"));
  }
  return absl::OkStatus();
}

// A stored drawing's art is what ImportSvg guarantees (solver/core/art.h); an archive is
// untrusted, so it is checked like any input: finite numbers, |coordinate| <= 1e9, at most
// `max_points` points and SvgImportOptions::max_layers layers, colours 0xRRGGBB, opacities in
// [0, 1], positive stroke widths, non-negative dashes.
absl::Status CheckArt(const std::vector<solver::ArtLayer>& art, absl::string_view field,
                      int max_points) {
  const int max_layers = solver::SvgImportOptions().max_layers;
  if (art.size() > static_cast<size_t>(max_layers)) {
    return absl::ResourceExhaustedError(
        absl::StrCat(field, ".art has ", art.size(), " layers, the limit is ", max_layers));
  }
  size_t total_points = 0;
  for (size_t i = 0; i < art.size(); ++i) {
    const solver::ArtLayer& layer = art[i];
    const std::string where =
        absl::StrCat(field, ".art[", i, "]", layer.id.empty() ? "" : " (id \"", layer.id,
                     layer.id.empty() ? "" : "\")");
    auto bad = [&](absl::string_view what, double value, absl::string_view range) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, ".", what, " = ", value, " is not ", range));
    };
    for (size_t k = 0; k < layer.paths.size(); ++k) {
      total_points += layer.paths[k].points.size();
      if (total_points > static_cast<size_t>(max_points)) {
        return absl::ResourceExhaustedError(
            absl::StrCat(field, ".art has more than ", max_points,
                         " points (limit per drawing, --max-drawing-points)"));
      }
      if (absl::Status s =
              CheckPoints(layer.paths[k].points, absl::StrCat(where, ".paths[", k, "]"));
          !s.ok()) {
        return s;
      }
    }
    auto unit = [](double v) { return v >= 0 && v <= 1; };  // false for NaN
    if (!unit(layer.opacity)) return bad("opacity", layer.opacity, "in [0, 1]");
    auto bad_rgb = [&](absl::string_view what, uint32_t rgb) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, ".", what, " = 0x", absl::Hex(rgb), " is not 0xRRGGBB"));
    };
    if (layer.fill) {
      if (layer.fill->rgb > 0xffffff) return bad_rgb("fill.rgb", layer.fill->rgb);
      if (!unit(layer.fill->opacity)) return bad("fill.opacity", layer.fill->opacity, "in [0, 1]");
    }
    if (layer.stroke) {
      const solver::StrokePaint& stroke = *layer.stroke;
      if (stroke.rgb > 0xffffff) return bad_rgb("stroke.rgb", stroke.rgb);
      if (!unit(stroke.opacity)) return bad("stroke.opacity", stroke.opacity, "in [0, 1]");
      if (!(std::isfinite(stroke.width) && stroke.width > 0)) {
        return bad("stroke.width", stroke.width, "finite and positive");
      }
      if (!std::isfinite(stroke.miter_limit)) {
        return bad("stroke.miter_limit", stroke.miter_limit, "finite");
      }
      if (!std::isfinite(stroke.dash_offset)) {
        return bad("stroke.dash_offset", stroke.dash_offset, "finite");
      }
      for (size_t k = 0; k < stroke.dashes.size(); ++k) {
        if (!(std::isfinite(stroke.dashes[k]) && stroke.dashes[k] >= 0)) {
          return bad(absl::StrCat("stroke.dashes[", k, "]"), stroke.dashes[k],
                     "finite and non-negative");
        }
      }
    }
  }
  return absl::OkStatus();
}

// PutDrawingRequest.gap_tolerance or .min_area_fraction (`name`) for ImportSvg: 0 -> `fallback`
// (SvgImportOptions' default), negative -> 0 (off), else checked against (0, kMaxImportFraction].
absl::StatusOr<double> ImportFraction(double value, double fallback, absl::string_view name) {
  if (value == 0) return fallback;
  if (!std::isfinite(value)) {
    return absl::InvalidArgumentError(absl::StrCat(name, " = ", value, " is not finite"));
  }
  if (value > kMaxImportFraction) {
    return absl::InvalidArgumentError(absl::StrCat(name, " = ", value, " is not in (0, ",
                                                   kMaxImportFraction, "] (0 = the default ",
                                                   fallback, ", negative = off)"));
  }
  return value < 0 ? 0.0 : value;
}

void AddElement(v1::ElementKind kind, const solver::Points& points, TopologyElements* out) {
  v1::TopologyElement* element = out->Add();
  element->set_id(static_cast<uint32_t>(out->size()));
  element->set_kind(kind);
  ToProto(points, element->mutable_polyline()->mutable_points());
}

}  // namespace

v1::EquivalenceClass ToProto(const solver::EquivalenceClass& equivalence) {
  v1::EquivalenceClass out;
  out.set_components(static_cast<uint32_t>(equivalence.components));
  out.set_holes(static_cast<uint32_t>(equivalence.holes));
  return out;
}

absl::StatusOr<ImportedDrawing> ImportDrawing(const v1::Drawing& drawing,
                                              const DrawingImportOptions& import_options,
                                              absl::string_view field, int drawing_number,
                                              const TopologyElements& topology,
                                              absl::string_view topology_field, int max_points) {
  if (absl::Status s = CheckDrawingFields(drawing, field); !s.ok()) return s;
  solver::SvgImportOptions options;
  const double flatten_tolerance = import_options.flatten_tolerance == 0
                                       ? kDefaultFlattenTolerance
                                       : import_options.flatten_tolerance;
  if (!(std::isfinite(flatten_tolerance) && flatten_tolerance > 0 && flatten_tolerance <= 1e6)) {
    return absl::InvalidArgumentError(
        absl::StrCat("flatten_tolerance = ", flatten_tolerance, " is not in (0, 1e6]"));
  }
  options.tolerance = flatten_tolerance;
  options.max_points = max_points;
  absl::StatusOr<double> gap =
      ImportFraction(import_options.gap_tolerance, options.gap_tolerance, "gap_tolerance");
  if (!gap.ok()) return gap.status();
  options.gap_tolerance = *gap;
  absl::StatusOr<double> min_area = ImportFraction(import_options.min_area_fraction,
                                                   options.min_area_fraction, "min_area_fraction");
  if (!min_area.ok()) return min_area.status();
  options.min_area_fraction = *min_area;
  for (int i = 0; i < topology.size(); ++i) {
    const v1::TopologyElement& element = topology[i];
    if (element.kind() != v1::ELEMENT_KIND_CUT && element.kind() != v1::ELEMENT_KIND_OPENING) {
      return absl::InvalidArgumentError(absl::StrCat(
          topology_field, "[", i, "].kind must be ELEMENT_KIND_CUT or ELEMENT_KIND_OPENING"));
    }
    if (element.id() != 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          topology_field, "[", i, "].id = ", element.id(), ": new elements have id 0"));
    }
  }
  TopologyElements elements;
  std::vector<solver::CorrespondenceMark> svg_marks;
  std::vector<solver::ArtLayer> art;
  solver::SvgImportInfo info;  // polylines: source ELEMENTS, no cleaning, no warnings
  std::string element_field;
  switch (drawing.source_case()) {
    case v1::Drawing::kSvg: {
      if (drawing.svg().empty()) {
        return absl::InvalidArgumentError(absl::StrCat(field, ".svg is empty"));
      }
      absl::StatusOr<solver::Drawing> parsed = solver::ImportSvg(drawing.svg(), options, &info);
      if (!parsed.ok()) {
        const bool limit = solver::ErrorReason(parsed.status()) == solver::kReasonDrawingPointLimit;
        return absl::Status(
            parsed.status().code(),
            absl::StrCat(field, ".svg: ", parsed.status().message(),
                         limit ? " (limit per drawing, --max-drawing-points)" : ""));
      }
      if (parsed->outlines.empty()) {
        return absl::InvalidArgumentError(absl::StrCat(field, ".svg has no filled shapes"));
      }
      if (absl::Status s = CheckArt(parsed->art, field, max_points); !s.ok()) return s;
      svg_marks = parsed->marks;
      art = std::move(parsed->art);
      for (const solver::Outline& o : parsed->outlines) {
        AddElement(v1::ELEMENT_KIND_OUTLINE, o.points, &elements);
      }
      for (const solver::Points& c : parsed->cuts) AddElement(v1::ELEMENT_KIND_CUT, c, &elements);
      for (const solver::Points& o : parsed->openings) {
        AddElement(v1::ELEMENT_KIND_OPENING, o, &elements);
      }
      element_field = absl::StrCat(field, ".svg element");
      break;
    }
    case v1::Drawing::kPolylines:
      elements = drawing.polylines().elements();
      for (int i = 0; i < elements.size(); ++i) elements[i].set_id(static_cast<uint32_t>(i + 1));
      element_field = absl::StrCat(field, ".polylines.elements");
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat(field, " has no source: set ", field, ".svg or ", field, ".polylines"));
  }
  // The added elements are checked under `topology_field` first, so that Analyze's per-element
  // messages can only be about the source's elements. Graph-flow messages count cuts and
  // openings 1-based in element order ("drawing 2, cut 1").
  for (int i = 0; i < topology.size(); ++i) {
    const std::string where = absl::StrCat(topology_field, "[", i, "]");
    if (absl::Status s = CheckOpenPolyline(FromProto(topology[i].polyline().points()), where);
        !s.ok()) {
      return s;
    }
    v1::TopologyElement* element = elements.Add();
    *element = topology[i];
    element->set_id(static_cast<uint32_t>(elements.size()));
  }
  absl::StatusOr<ImportedDrawing> out =
      Analyze(std::move(elements), field, element_field, false, drawing_number, max_points);
  if (out.ok()) {
    out->parsed.marks = drawing.has_svg() ? svg_marks : MarksOf(drawing);
    out->import_report = ToProto(info, static_cast<int>(art.size()));
    out->parsed.art = std::move(art);
  }
  return out;
}

absl::StatusOr<ImportedDrawing> ImportDrawingElements(const v1::Drawing& drawing,
                                                      absl::string_view field, int drawing_number,
                                                      int max_points) {
  if (absl::Status s = CheckDrawingFields(drawing, field); !s.ok()) return s;
  TopologyElements elements = drawing.elements();
  std::set<uint32_t> ids;
  uint32_t max_id = 0;
  for (int i = 0; i < elements.size(); ++i) {
    const uint32_t id = elements[i].id();
    if (id == 0) continue;
    if (!ids.insert(id).second) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".elements[", i, "].id = ", id, " is repeated"));
    }
    max_id = std::max(max_id, id);
  }
  for (v1::TopologyElement& element : elements) {
    if (element.id() == 0) element.set_id(++max_id);
  }
  std::vector<solver::ArtLayer> art = FromProto(drawing.art());
  if (absl::Status s = CheckArt(art, field, max_points); !s.ok()) return s;
  absl::StatusOr<ImportedDrawing> out = Analyze(
      std::move(elements), field, absl::StrCat(field, ".elements"), true, drawing_number, max_points);
  if (out.ok()) {
    out->parsed.marks = MarksOf(drawing);
    out->parsed.art = std::move(art);
    out->import_report = drawing.import_report();
    out->import_report.set_art_layers(static_cast<uint32_t>(out->parsed.art.size()));
  }
  return out;
}

void StoreImport(const ImportedDrawing& imported, v1::Drawing* drawing) {
  *drawing->mutable_elements() = imported.elements;
  SetMarks(imported.parsed.marks, drawing);
  drawing->clear_art();
  ToProto(imported.parsed.art, drawing->mutable_art());
  *drawing->mutable_import_report() = imported.import_report;
}

std::vector<solver::CorrespondenceMark> MarksOf(const v1::Drawing& drawing) {
  std::vector<solver::CorrespondenceMark> marks;
  for (const v1::DrawingMark& mark : drawing.marks()) {
    marks.push_back({static_cast<int>(mark.id()), solver::Point(mark.point().x(), mark.point().y())});
  }
  return marks;
}

void SetMarks(const std::vector<solver::CorrespondenceMark>& marks, v1::Drawing* drawing) {
  drawing->clear_marks();
  for (const solver::CorrespondenceMark& mark : marks) {
    v1::DrawingMark* out = drawing->add_marks();
    out->set_id(static_cast<uint32_t>(mark.id));
    out->mutable_point()->set_x(mark.point.x());
    out->mutable_point()->set_y(mark.point.y());
  }
}

}  // namespace inbetween::server
