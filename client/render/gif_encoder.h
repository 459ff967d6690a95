// Animated GIF encoding with giflib: GIF89a, looping via the NETSCAPE2.0 application extension,
// per-frame delays from the frame rate, one global palette built for the animation's colours.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/render/color.h"
#include "client/render/rgba_image.h"

namespace inbetween::render {

struct GifOptions {
  double fps = 24;
  int loop_count = 0;        // 0 = loop forever
  bool transparent = false;  // palette index 0 is transparent; pixels with alpha < 128 use it
  // The colours frames are made of (background, fill, overlay). The palette holds ramps between
  // every pair, which covers anti-aliased edges; empty = a generic 6x7x6 colour cube.
  std::vector<Rgba8> palette_colors;
};

// The global palette for `options` (at most 256 colours; index 0 transparent if requested).
std::vector<Rgba8> GifPalette(const GifOptions& options);

// Delay of frame `frame` in centiseconds. Rounded cumulatively so that the average matches
// `fps`; at least 2 (browsers slow smaller delays down to 10).
int GifDelayCentiseconds(int frame, double fps);

// Streams frames into an in-memory GIF. Opaque animations store only the rectangle that changed
// since the previous frame; transparent ones store whole frames disposed to the background.
class GifEncoder {
 public:
  static absl::StatusOr<GifEncoder> Create(int width, int height, GifOptions options = {});
  GifEncoder(GifEncoder&&) noexcept;
  GifEncoder& operator=(GifEncoder&&) noexcept;
  ~GifEncoder();

  // `image` must have the encoder's size.
  absl::Status AddFrame(const RgbaImage& image);

  // The GIF file bytes; the encoder is spent afterwards.
  absl::StatusOr<std::string> Finish();

 private:
  struct Impl;
  explicit GifEncoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace inbetween::render
