// Sequence viewport (see viewport.h).
#include "client/render/viewport.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "client/render/bounds.h"

namespace inbetween::render {

absl::StatusOr<Viewport> FrameSetViewport(const FrameSet& frames, int width) {
  if (width < 1 || width > kMaxImageSide) {
    return absl::InvalidArgumentError(
        absl::StrCat("output width ", width, " px is outside [1, ", kMaxImageSide, "]"));
  }
  const Bounds b = FrameSetBounds(frames);
  if (frames.frames.empty() || !(b.extent() > 0.0) || !std::isfinite(b.extent())) {
    return absl::InvalidArgumentError(
        "the frames have no extent to render (no frames, or every vertex at one point)");
  }
  const double margin = 0.05 * b.extent();  // same margin as the SVG viewBox
  Viewport v;
  v.scale = width / (b.width() + 2 * margin);
  v.origin_x = b.min_x - margin;
  v.origin_y = b.min_y - margin;
  v.width = width;
  v.height = std::max(1, static_cast<int>(std::lround((b.height() + 2 * margin) * v.scale)));
  if (v.height > kMaxImageSide) {
    return absl::InvalidArgumentError(absl::StrCat("output height ", v.height, " px (width ", width,
                                                   ") exceeds ", kMaxImageSide,
                                                   "; choose a smaller size"));
  }
  return v;
}

}  // namespace inbetween::render
