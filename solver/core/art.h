// A drawing's art: every painted element of an SVG document, in paint order, as ImportSvg keeps
// it (docs/svg-convention.md, "Layers of paint"). Geometry is flattened to the import tolerance
// and given in the drawing's coordinates (every transform applied), so that a renderer or the
// mesh embedding needs no SVG knowledge.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "solver/core/point.h"

namespace inbetween::solver {

enum class LineCap { kButt, kRound, kSquare };
enum class LineJoin { kMiter, kRound, kBevel };

// A fill: a plain colour (a gradient arrives as the mean of its stops, with an import warning).
struct FillPaint {
  uint32_t rgb = 0;       // 0xRRGGBB
  double opacity = 1.0;   // fill-opacity, in [0, 1]
  bool even_odd = false;  // fill-rule: evenodd (true) or nonzero (false)
};

// A stroke, in the drawing's coordinates: `width` and `dashes` are scaled by the element's
// transform (by sqrt|det| of its linear part, exact for rotations and uniform scales).
struct StrokePaint {
  uint32_t rgb = 0;
  double opacity = 1.0;  // stroke-opacity, in [0, 1]
  double width = 1.0;    // > 0
  LineCap cap = LineCap::kButt;
  LineJoin join = LineJoin::kMiter;
  double miter_limit = 4.0;    // SVG's stroke-miterlimit (ratio of miter length to width)
  std::vector<double> dashes;  // stroke-dasharray (even count; empty = solid)
  double dash_offset = 0.0;
};

// One subpath of a layer, flattened. A closed subpath does not repeat its first point.
struct ArtPath {
  Points points;
  bool closed = false;
};

// One painted element (path, rect, circle, ellipse, line, polyline, polygon).
struct ArtLayer {
  std::string id;    // the element's id attribute, or empty
  std::string name;  // its data-layer attribute (matches layers across drawings), or empty
  std::vector<ArtPath> paths;
  std::optional<FillPaint> fill;      // nullopt: not filled (fill="none")
  std::optional<StrokePaint> stroke;  // nullopt: not stroked
  // The element's opacity times its ancestors' (group opacity is applied per element, which
  // equals SVG's group compositing wherever the group's children do not overlap).
  double opacity = 1.0;
};

}  // namespace inbetween::solver
