// Art layers through cairo (see art_painter.h).
#include "client/render/art_painter.h"

#include <cairo.h>

#include "client/render/cairo_image.h"

namespace inbetween::render {
namespace {

void SetRgb(cairo_t* cr, uint32_t rgb, double alpha) {
  cairo_set_source_rgba(cr, ((rgb >> 16) & 0xff) / 255.0, ((rgb >> 8) & 0xff) / 255.0,
                        (rgb & 0xff) / 255.0, alpha);
}

// Every subpath of the layer as one cairo path, so that the fill rule sees them together (as
// SVG fills one element's subpaths).
void AppendPath(cairo_t* cr, const solver::ArtLayer& layer, const Viewport& viewport) {
  for (const solver::ArtPath& path : layer.paths) {
    for (size_t i = 0; i < path.points.size(); ++i) {
      const auto [x, y] = viewport.ToPixels({path.points[i].x(), path.points[i].y()});
      if (i == 0) {
        cairo_move_to(cr, x, y);
      } else {
        cairo_line_to(cr, x, y);
      }
    }
    if (path.closed && !path.points.empty()) cairo_close_path(cr);
  }
}

void SetStroke(cairo_t* cr, const solver::StrokePaint& s, double scale) {
  cairo_set_line_width(cr, s.width * scale);
  switch (s.cap) {
    case solver::LineCap::kRound:
      cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
      break;
    case solver::LineCap::kSquare:
      cairo_set_line_cap(cr, CAIRO_LINE_CAP_SQUARE);
      break;
    default:
      cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  }
  switch (s.join) {
    case solver::LineJoin::kRound:
      cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
      break;
    case solver::LineJoin::kBevel:
      cairo_set_line_join(cr, CAIRO_LINE_JOIN_BEVEL);
      break;
    default:
      cairo_set_line_join(cr, CAIRO_LINE_JOIN_MITER);
  }
  // SVG's stroke-miterlimit and cairo's miter limit are the same ratio (miter length / width).
  cairo_set_miter_limit(cr, s.miter_limit);
  // A dash array of zero total length draws a solid line in SVG; cairo would reject it.
  double total = 0;
  for (double d : s.dashes) total += d;
  if (total > 0) {
    std::vector<double> dashes;
    for (double d : s.dashes) dashes.push_back(d * scale);
    cairo_set_dash(cr, dashes.data(), static_cast<int>(dashes.size()), s.dash_offset * scale);
  } else {
    cairo_set_dash(cr, nullptr, 0, 0);
  }
}

}  // namespace

void PaintArt(cairo_t* cr, const std::vector<solver::ArtLayer>& layers, const Viewport& viewport) {
  cairo_save(cr);
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_DEFAULT);
  for (const solver::ArtLayer& layer : layers) {
    if ((!layer.fill && !layer.stroke) || layer.paths.empty() || !(layer.opacity > 0)) continue;
    const bool group = layer.fill && layer.stroke && layer.opacity < 1;
    const double alpha = group ? 1.0 : layer.opacity;  // see the header: group or multiply
    if (group) cairo_push_group(cr);
    cairo_new_path(cr);
    AppendPath(cr, layer, viewport);
    if (layer.fill) {
      cairo_set_fill_rule(
          cr, layer.fill->even_odd ? CAIRO_FILL_RULE_EVEN_ODD : CAIRO_FILL_RULE_WINDING);
      SetRgb(cr, layer.fill->rgb, layer.fill->opacity * alpha);
      cairo_fill_preserve(cr);
    }
    if (layer.stroke && layer.stroke->width > 0) {
      SetStroke(cr, *layer.stroke, viewport.scale);
      SetRgb(cr, layer.stroke->rgb, layer.stroke->opacity * alpha);
      cairo_stroke_preserve(cr);
    }
    cairo_new_path(cr);
    if (group) {
      cairo_pop_group_to_source(cr);
      cairo_paint_with_alpha(cr, layer.opacity);
    }
  }
  cairo_restore(cr);
}

RgbaImage RenderArt(const std::vector<solver::ArtLayer>& layers, const Viewport& viewport,
                    const Rgba8& background) {
  CairoSurface surface(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, viewport.width, viewport.height));
  Cairo cr(cairo_create(surface.get()));
  if (background.a > 0) {
    cairo_set_source_rgba(cr.get(), background.r / 255.0, background.g / 255.0,
                          background.b / 255.0, background.a / 255.0);
    cairo_paint(cr.get());
  }
  PaintArt(cr.get(), layers, viewport);
  return ImageFromSurface(surface.get());
}

}  // namespace inbetween::render
