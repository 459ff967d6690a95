// RgbaImage <-> cairo surface (see cairo_image.h).
#include "client/render/cairo_image.h"

#include <cstring>

namespace inbetween::render {

RgbaImage ImageFromSurface(cairo_surface_t* surface) {
  const int w = cairo_image_surface_get_width(surface);
  const int h = cairo_image_surface_get_height(surface);
  CairoSurface argb;
  if (cairo_image_surface_get_format(surface) != CAIRO_FORMAT_ARGB32) {
    argb.reset(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h));
    Cairo cr(cairo_create(argb.get()));
    cairo_set_source_surface(cr.get(), surface, 0, 0);
    cairo_set_operator(cr.get(), CAIRO_OPERATOR_SOURCE);
    cairo_paint(cr.get());
    surface = argb.get();
  }
  cairo_surface_flush(surface);
  const unsigned char* data = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  RgbaImage image(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      uint32_t argb_px;
      std::memcpy(&argb_px, data + static_cast<size_t>(y) * stride + 4 * x, 4);
      const uint32_t a = argb_px >> 24;
      uint8_t* out = &image.rgba[(static_cast<size_t>(y) * w + x) * 4];
      for (int c = 0; c < 3; ++c) {
        const uint32_t premul = (argb_px >> (16 - 8 * c)) & 0xff;
        out[c] =
            a == 0 ? 0 : static_cast<uint8_t>(std::min<uint32_t>(255, (premul * 255 + a / 2) / a));
      }
      out[3] = static_cast<uint8_t>(a);
    }
  }
  return image;
}

CairoSurface SurfaceFromImage(const RgbaImage& image) {
  CairoSurface surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, image.width, image.height));
  cairo_surface_flush(surface.get());
  unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const uint8_t* in = &image.rgba[(static_cast<size_t>(y) * image.width + x) * 4];
      const uint32_t a = in[3];
      uint32_t px = a << 24;
      for (int c = 0; c < 3; ++c) px |= ((in[c] * a + 127) / 255) << (16 - 8 * c);
      std::memcpy(data + static_cast<size_t>(y) * stride + 4 * x, &px, 4);
    }
  }
  cairo_surface_mark_dirty(surface.get());
  return surface;
}

}  // namespace inbetween::render
