// Art layers as SVG <path> elements (see art_svg.h).
#include "solver/art/art_svg.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace inbetween::solver {
namespace {

std::string Color(uint32_t rgb) { return absl::StrFormat("#%06x", rgb & 0xFFFFFF); }

std::string Number(double v) { return absl::StrFormat("%.9g", v); }

std::string Escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string PathData(const std::vector<ArtPath>& paths) {
  std::string d;
  for (const ArtPath& path : paths) {
    for (size_t i = 0; i < path.points.size(); ++i) {
      absl::StrAppend(&d, d.empty() ? "" : " ", i == 0 ? "M" : "L", Number(path.points[i].x()), " ",
                      Number(path.points[i].y()));
    }
    if (path.closed && !path.points.empty()) absl::StrAppend(&d, "Z");
  }
  return d;
}

void AppendFill(const std::optional<FillPaint>& fill, std::string* out) {
  if (!fill) {
    absl::StrAppend(out, " fill=\"none\"");
    return;
  }
  absl::StrAppend(out, " fill=\"", Color(fill->rgb), "\"");
  if (fill->opacity != 1.0) absl::StrAppend(out, " fill-opacity=\"", Number(fill->opacity), "\"");
  if (fill->even_odd) absl::StrAppend(out, " fill-rule=\"evenodd\"");
}

void AppendStroke(const std::optional<StrokePaint>& stroke, std::string* out) {
  if (!stroke) {
    absl::StrAppend(out, " stroke=\"none\"");
    return;
  }
  const StrokePaint& s = *stroke;
  absl::StrAppend(out, " stroke=\"", Color(s.rgb), "\" stroke-width=\"", Number(s.width), "\"");
  if (s.opacity != 1.0) absl::StrAppend(out, " stroke-opacity=\"", Number(s.opacity), "\"");
  if (s.cap == LineCap::kRound) absl::StrAppend(out, " stroke-linecap=\"round\"");
  if (s.cap == LineCap::kSquare) absl::StrAppend(out, " stroke-linecap=\"square\"");
  if (s.join == LineJoin::kRound) absl::StrAppend(out, " stroke-linejoin=\"round\"");
  if (s.join == LineJoin::kBevel) absl::StrAppend(out, " stroke-linejoin=\"bevel\"");
  if (s.join == LineJoin::kMiter && s.miter_limit != 4.0) {
    absl::StrAppend(out, " stroke-miterlimit=\"", Number(s.miter_limit), "\"");
  }
  if (!s.dashes.empty()) {
    std::string dashes;
    for (double d : s.dashes) absl::StrAppend(&dashes, dashes.empty() ? "" : " ", Number(d));
    absl::StrAppend(out, " stroke-dasharray=\"", dashes, "\"");
    if (s.dash_offset != 0.0) {
      absl::StrAppend(out, " stroke-dashoffset=\"", Number(s.dash_offset), "\"");
    }
  }
}

}  // namespace

std::string ArtToSvgPaths(const std::vector<ArtLayer>& layers) {
  std::string out;
  for (const ArtLayer& layer : layers) {
    if (!layer.fill && !layer.stroke) continue;
    const std::string d = PathData(layer.paths);
    if (d.empty()) continue;
    absl::StrAppend(&out, "<path");
    if (!layer.name.empty()) absl::StrAppend(&out, " data-layer=\"", Escaped(layer.name), "\"");
    AppendFill(layer.fill, &out);
    AppendStroke(layer.stroke, &out);
    if (layer.opacity != 1.0) absl::StrAppend(&out, " opacity=\"", Number(layer.opacity), "\"");
    absl::StrAppend(&out, " d=\"", d, "\"/>\n");
  }
  return out;
}

}  // namespace inbetween::solver
