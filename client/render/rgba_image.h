// An 8-bit RGBA image (straight alpha, row-major): what the rasterizer produces and the PNG, GIF
// and WebP encoders consume.
#pragma once

#include <cstdint>
#include <vector>

#include "client/render/color.h"

namespace inbetween::render {

struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes

  RgbaImage() = default;
  RgbaImage(int w, int h) : width(w), height(h), rgba(static_cast<size_t>(w) * h * 4, 0) {}

  Rgba8 Pixel(int x, int y) const {
    const uint8_t* p = &rgba[(static_cast<size_t>(y) * width + x) * 4];
    return {p[0], p[1], p[2], p[3]};
  }
};

}  // namespace inbetween::render
