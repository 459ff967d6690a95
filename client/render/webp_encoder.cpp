// Animated WebP encoder (see webp_encoder.h).
#include "client/render/webp_encoder.h"

#include <webp/encode.h>
#include <webp/mux.h>

#include <cmath>

#include "absl/strings/str_cat.h"

namespace inbetween::render {
namespace {

int TimestampMs(int frame, double fps) {
  return static_cast<int>(std::lround(1000.0 * frame / fps));
}

}  // namespace

struct WebpEncoder::Impl {
  WebPAnimEncoder* encoder = nullptr;
  WebPConfig config;
  int width = 0, height = 0;
  double fps = 24;
  int frames = 0;

  ~Impl() {
    if (encoder != nullptr) WebPAnimEncoderDelete(encoder);
  }
  absl::Status Error(const std::string& what) const {
    const char* detail = encoder != nullptr ? WebPAnimEncoderGetError(encoder) : nullptr;
    return absl::InternalError(
        absl::StrCat("WebP encoding: ", what, detail != nullptr ? absl::StrCat(": ", detail) : ""));
  }
};

WebpEncoder::WebpEncoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WebpEncoder::WebpEncoder(WebpEncoder&&) noexcept = default;
WebpEncoder& WebpEncoder::operator=(WebpEncoder&&) noexcept = default;
WebpEncoder::~WebpEncoder() = default;

absl::StatusOr<WebpEncoder> WebpEncoder::Create(int width, int height, WebpOptions options) {
  if (width < 1 || height < 1 || width > WEBP_MAX_DIMENSION || height > WEBP_MAX_DIMENSION) {
    return absl::InvalidArgumentError(
        absl::StrCat("WebP size ", width, " x ", height, " is outside 1..", WEBP_MAX_DIMENSION));
  }
  if (!(options.fps > 0) || !std::isfinite(options.fps)) {
    return absl::InvalidArgumentError(
        absl::StrCat("WebP frame rate ", options.fps, " must be positive"));
  }
  if (!(options.quality >= 0 && options.quality <= 100)) {
    return absl::InvalidArgumentError(
        absl::StrCat("WebP quality ", options.quality, " is outside 0..100"));
  }
  auto impl = std::make_unique<Impl>();
  impl->width = width;
  impl->height = height;
  impl->fps = options.fps;
  if (!WebPConfigInit(&impl->config)) return impl->Error("library version mismatch");
  impl->config.lossless = options.lossless ? 1 : 0;
  impl->config.quality = options.quality;
  impl->config.method = 4;
  if (!WebPValidateConfig(&impl->config)) return impl->Error("invalid configuration");
  WebPAnimEncoderOptions anim;
  if (!WebPAnimEncoderOptionsInit(&anim)) return impl->Error("library version mismatch");
  anim.anim_params.loop_count = std::max(0, options.loop_count);
  anim.anim_params.bgcolor = 0x00ffffff;  // transparent white (players mostly ignore it)
  impl->encoder = WebPAnimEncoderNew(width, height, &anim);
  if (impl->encoder == nullptr) return impl->Error("cannot create the animation encoder");
  return WebpEncoder(std::move(impl));
}

absl::Status WebpEncoder::AddFrame(const RgbaImage& image) {
  Impl& s = *impl_;
  if (s.encoder == nullptr) return absl::FailedPreconditionError("WebP encoder already finished");
  if (image.width != s.width || image.height != s.height) {
    return absl::InvalidArgumentError(absl::StrCat("WebP frame is ", image.width, " x ",
                                                   image.height, ", the animation is ", s.width,
                                                   " x ", s.height));
  }
  WebPPicture picture;
  if (!WebPPictureInit(&picture)) return s.Error("library version mismatch");
  picture.use_argb = 1;
  picture.width = image.width;
  picture.height = image.height;
  if (!WebPPictureImportRGBA(&picture, image.rgba.data(), 4 * image.width)) {
    WebPPictureFree(&picture);
    return s.Error("out of memory importing a frame");
  }
  const int ok = WebPAnimEncoderAdd(s.encoder, &picture, TimestampMs(s.frames, s.fps), &s.config);
  WebPPictureFree(&picture);
  if (!ok) return s.Error(absl::StrCat("frame ", s.frames));
  ++s.frames;
  return absl::OkStatus();
}

absl::StatusOr<std::string> WebpEncoder::Finish() {
  Impl& s = *impl_;
  if (s.encoder == nullptr) return absl::FailedPreconditionError("WebP encoder already finished");
  if (s.frames == 0) return absl::FailedPreconditionError("WebP animation has no frames");
  // A final NULL frame sets the duration of the last real frame.
  if (!WebPAnimEncoderAdd(s.encoder, nullptr, TimestampMs(s.frames, s.fps), nullptr)) {
    return s.Error("closing the last frame");
  }
  WebPData data;
  WebPDataInit(&data);
  if (!WebPAnimEncoderAssemble(s.encoder, &data)) return s.Error("assembling the file");
  std::string bytes(reinterpret_cast<const char*>(data.bytes), data.size);
  WebPDataClear(&data);
  WebPAnimEncoderDelete(s.encoder);
  s.encoder = nullptr;
  return bytes;
}

}  // namespace inbetween::render
