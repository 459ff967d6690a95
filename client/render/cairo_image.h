// Internal to inbetween_render: conversions between RgbaImage (straight alpha) and cairo image
// surfaces (premultiplied native-endian ARGB32). Only .cpp files of client/render include cairo.
#pragma once

#include <cairo.h>

#include <memory>

#include "client/render/rgba_image.h"

namespace inbetween::render {

struct CairoSurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct CairoDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};
using CairoSurface = std::unique_ptr<cairo_surface_t, CairoSurfaceDeleter>;
using Cairo = std::unique_ptr<cairo_t, CairoDeleter>;

// Copies any image surface (converted to ARGB32 first if needed) into an RgbaImage.
RgbaImage ImageFromSurface(cairo_surface_t* surface);

// A new ARGB32 surface holding `image`.
CairoSurface SurfaceFromImage(const RgbaImage& image);

}  // namespace inbetween::render
