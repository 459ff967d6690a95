// Animated WebP encoding with libwebp's WebPAnimEncoder: lossless (default) or lossy at a
// quality, frame timestamps from the frame rate, looping forever by default.
#pragma once

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "client/render/rgba_image.h"

namespace inbetween::render {

struct WebpOptions {
  double fps = 24;
  bool lossless = true;  // flat-colour shapes compress well losslessly and stay exact
  float quality = 80;    // 0..100: lossy quality, or compression effort when lossless
  int loop_count = 0;    // 0 = loop forever
};

// Streams frames into an in-memory animated WebP.
class WebpEncoder {
 public:
  static absl::StatusOr<WebpEncoder> Create(int width, int height, WebpOptions options = {});
  WebpEncoder(WebpEncoder&&) noexcept;
  WebpEncoder& operator=(WebpEncoder&&) noexcept;
  ~WebpEncoder();

  // `image` must have the encoder's size.
  absl::Status AddFrame(const RgbaImage& image);

  // The WebP file bytes; the encoder is spent afterwards.
  absl::StatusOr<std::string> Finish();

 private:
  struct Impl;
  explicit WebpEncoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace inbetween::render
