// Cairo painting of a drawing's art layers (solver/core/art.h) through a Viewport: fills with
// their fill rule and opacity, strokes with width, caps, joins, miter limit and dashes, all
// anti-aliased, in paint order. Used by the raster frames (PNG, GIF, WebP, contact sheet).
//
// Layer opacity: a layer with both a fill and a stroke and opacity < 1 is drawn into a group
// (cairo_push_group) that is then painted with that opacity, as SVG composites an element's
// opacity: where its stroke covers its fill, the fill does not show through. Every other layer
// multiplies its opacity into its paint's alpha, which gives the same pixels without the
// group's extra surface.
#pragma once

#include <vector>

#include "client/render/color.h"
#include "client/render/rgba_image.h"
#include "client/render/viewport.h"
#include "solver/core/art.h"

typedef struct _cairo cairo_t;  // NOLINT: cairo's own declaration, so cairo.h stays internal

namespace inbetween::render {

// Paints `layers` onto `cr` (user units -> pixels by `viewport`; stroke widths and dashes scale
// with it). Leaves the context's state as it found it.
void PaintArt(cairo_t* cr, const std::vector<solver::ArtLayer>& layers, const Viewport& viewport);

// `layers` painted on a `viewport.width` x `viewport.height` image over `background`.
RgbaImage RenderArt(const std::vector<solver::ArtLayer>& layers, const Viewport& viewport,
                    const Rgba8& background);

}  // namespace inbetween::render
