// Axis-aligned bounds of a frame set (every frame), shared by the SVG and raster exporters.
#pragma once

#include <algorithm>
#include <limits>

#include "client/render/frame_set.h"

namespace inbetween::render {

struct Bounds {
  double min_x = std::numeric_limits<double>::infinity();
  double min_y = std::numeric_limits<double>::infinity();
  double max_x = -std::numeric_limits<double>::infinity();
  double max_y = -std::numeric_limits<double>::infinity();

  void Add(const Vertex& p) {
    min_x = std::min(min_x, p[0]);
    min_y = std::min(min_y, p[1]);
    max_x = std::max(max_x, p[0]);
    max_y = std::max(max_y, p[1]);
  }
  double width() const { return max_x - min_x; }
  double height() const { return max_y - min_y; }
  double extent() const { return std::max(width(), height()); }
};

inline Bounds FrameSetBounds(const FrameSet& frames) {
  Bounds b;
  for (const auto& f : frames.frames) {
    for (const auto& p : f.vertices) b.Add(p);
  }
  return b;
}

}  // namespace inbetween::render
