// Raster rendering of frames with cairo: the drawings' art placed in the frame (FrameSet::art,
// art_painter.h), or without art the silhouette: the boundary loops filled anti-aliased with the
// nonzero rule (holes stay holes, overlapping parts stay filled); optionally the triangle edges
// on top, on a white or transparent background. Every frame of a set uses the same Viewport.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "client/render/boundary_loops.h"
#include "client/render/color.h"
#include "client/render/frame_set.h"
#include "client/render/rgba_image.h"
#include "client/render/viewport.h"

namespace inbetween::render {

struct RasterOptions {
  int width = 512;               // output width in pixels; the height follows the aspect ratio
  std::string fill = "#3b7dd8";  // shape colour (see ParseColor)
  bool drawing_fills = true;     // FrameSet::fills (blended per frame) win over `fill` when present
  bool mesh_overlay = false;     // draw the triangle edges on top
  bool transparent = false;      // transparent instead of white background
  // Draw FrameSet::art when the set has art; false (or no art): the one-colour silhouette.
  bool art = true;
};

// Colour of the mesh overlay lines.
inline constexpr Rgba8 kMeshOverlayColor = {34, 34, 34, 255};

// Set-up once per frame set (viewport, boundary loops, colours); renders any frame on demand.
// Keeps a reference to the FrameSet, which must outlive it.
class FrameRasterizer {
 public:
  // Fails on an invalid frame set (CheckFrameSet), bad colour, width or mesh orientation.
  static absl::StatusOr<FrameRasterizer> Create(const FrameSet& frames, RasterOptions options);

  // Frame `f` (position in frames.frames, not FrameData::index).
  RgbaImage Render(size_t f) const;

  const Viewport& viewport() const { return viewport_; }
  int width() const { return viewport_.width; }
  int height() const { return viewport_.height; }
  Rgba8 fill() const { return fill_; }
  // The colour frame `f` is filled with (`fill`, or the drawings' fills blended).
  Rgba8 FillOf(size_t f) const;
  Rgba8 background() const { return background_; }
  // Whether frames are drawn from the art (else as the silhouette).
  bool draws_art() const { return draw_art_; }
  const RasterOptions& options() const { return options_; }

 private:
  FrameRasterizer() = default;

  const FrameSet* frames_ = nullptr;
  RasterOptions options_;
  Viewport viewport_;
  Rgba8 fill_;
  std::vector<Rgba8> frame_fills_;  // per frame when the drawings' fills are used, else empty
  Rgba8 background_;
  bool draw_art_ = false;
  std::vector<Loop> loops_;
  std::vector<std::pair<int, int>> edges_;  // unique triangle edges, for the overlay
};

}  // namespace inbetween::render
