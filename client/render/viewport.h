// The one user-units -> pixels transform of a whole sequence: the union bounds of every frame
// plus a 5% margin (as the SVG viewBox), scaled to a fixed output width, so frames don't jump.
#pragma once

#include <array>

#include "absl/status/statusor.h"
#include "client/render/frame_set.h"

namespace inbetween::render {

struct Viewport {
  double scale = 1.0;     // pixels per user unit
  double origin_x = 0.0;  // user-space point mapped to pixel (0, 0)
  double origin_y = 0.0;
  int width = 0;  // pixels
  int height = 0;

  std::array<double, 2> ToPixels(const Vertex& p) const {
    return {(p[0] - origin_x) * scale, (p[1] - origin_y) * scale};
  }
};

// Largest accepted output side, in pixels (a 16k image is ~1 GiB of RGBA; larger is a typo).
inline constexpr int kMaxImageSide = 16384;

// The viewport of `frames` at `width` pixels; height follows the aspect ratio of the bounds.
// Fails on an empty frame set, bounds of zero extent or a width outside [1, kMaxImageSide].
absl::StatusOr<Viewport> FrameSetViewport(const FrameSet& frames, int width);

}  // namespace inbetween::render
