// Animated GIF encoder (see gif_encoder.h). Pixels map to the nearest palette colour (squared
// RGB distance), memoised per colour: shape-on-background frames have few distinct colours.
#include "client/render/gif_encoder.h"

#include <gif_lib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include "absl/strings/str_cat.h"

namespace inbetween::render {
namespace {

constexpr int kPaletteSize = 256;

int WriteToString(GifFileType* gif, const GifByteType* data, int length) {
  static_cast<std::string*>(gif->UserData)->append(reinterpret_cast<const char*>(data), length);
  return length;
}

}  // namespace

std::vector<Rgba8> GifPalette(const GifOptions& options) {
  std::vector<Rgba8> palette;
  if (options.transparent) palette.push_back({0, 0, 0, 0});
  std::vector<Rgba8> anchors;
  for (Rgba8 c : options.palette_colors) {
    c.a = 255;
    if (std::find(anchors.begin(), anchors.end(), c) == anchors.end()) anchors.push_back(c);
  }
  if (anchors.empty()) {
    for (int r = 0; r < 6; ++r) {
      for (int g = 0; g < 7; ++g) {
        for (int b = 0; b < 6; ++b) {
          palette.push_back({static_cast<uint8_t>(r * 51), static_cast<uint8_t>(g * 255 / 6),
                             static_cast<uint8_t>(b * 51), 255});
        }
      }
    }
    return palette;
  }
  anchors.resize(std::min<size_t>(anchors.size(), 16));
  palette.insert(palette.end(), anchors.begin(), anchors.end());
  const int pairs = static_cast<int>(anchors.size() * (anchors.size() - 1) / 2);
  if (pairs == 0) return palette;
  const int steps = (kPaletteSize - static_cast<int>(palette.size())) / pairs;  // per pair
  for (size_t i = 0; i < anchors.size(); ++i) {
    for (size_t j = i + 1; j < anchors.size(); ++j) {
      for (int s = 1; s <= steps; ++s) {
        const double t = static_cast<double>(s) / (steps + 1);
        const auto mix = [&](uint8_t a, uint8_t b) {
          return static_cast<uint8_t>(std::lround((1 - t) * a + t * b));
        };
        palette.push_back({mix(anchors[i].r, anchors[j].r), mix(anchors[i].g, anchors[j].g),
                           mix(anchors[i].b, anchors[j].b), 255});
      }
    }
  }
  return palette;
}

int GifDelayCentiseconds(int frame, double fps) {
  const auto at = [&](int f) { return std::lround(100.0 * f / fps); };
  return std::max(2, static_cast<int>(at(frame + 1) - at(frame)));
}

struct GifEncoder::Impl {
  GifFileType* gif = nullptr;
  std::string bytes;
  int width = 0, height = 0;
  GifOptions options;
  std::vector<Rgba8> palette;
  std::unordered_map<uint32_t, uint8_t> nearest;  // RGB -> palette index
  std::vector<uint8_t> previous;                  // indices of the last frame
  int frames = 0;

  ~Impl() {
    if (gif != nullptr) EGifCloseFile(gif, nullptr);
  }

  absl::Status Error(const std::string& what) const {
    return absl::InternalError(absl::StrCat("GIF encoding: ", what, ": ",
                                            GifErrorString(gif != nullptr ? gif->Error : 0)));
  }

  uint8_t Index(const uint8_t* px) {
    if (options.transparent && px[3] < 128) return 0;
    const uint32_t rgb = (uint32_t{px[0]} << 16) | (uint32_t{px[1]} << 8) | px[2];
    auto it = nearest.find(rgb);
    if (it != nearest.end()) return it->second;
    int best = 0;
    int best_d = INT32_MAX;
    for (size_t i = options.transparent ? 1 : 0; i < palette.size(); ++i) {
      const int dr = palette[i].r - px[0], dg = palette[i].g - px[1], db = palette[i].b - px[2];
      const int d = dr * dr + dg * dg + db * db;
      if (d < best_d) best_d = d, best = static_cast<int>(i);
    }
    if (nearest.size() > (1 << 16)) nearest.clear();  // arbitrary input: bound the memo
    nearest.emplace(rgb, static_cast<uint8_t>(best));
    return static_cast<uint8_t>(best);
  }
};

GifEncoder::GifEncoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GifEncoder::GifEncoder(GifEncoder&&) noexcept = default;
GifEncoder& GifEncoder::operator=(GifEncoder&&) noexcept = default;
GifEncoder::~GifEncoder() = default;

absl::StatusOr<GifEncoder> GifEncoder::Create(int width, int height, GifOptions options) {
  if (width < 1 || height < 1 || width > 65535 || height > 65535) {
    return absl::InvalidArgumentError(
        absl::StrCat("GIF size ", width, " x ", height, " is outside 1..65535"));
  }
  if (!(options.fps > 0) || !std::isfinite(options.fps)) {
    return absl::InvalidArgumentError(
        absl::StrCat("GIF frame rate ", options.fps, " must be positive"));
  }
  auto impl = std::make_unique<Impl>();
  impl->width = width;
  impl->height = height;
  impl->palette = GifPalette(options);
  impl->options = std::move(options);
  int error = 0;
  impl->gif = EGifOpen(&impl->bytes, WriteToString, &error);
  if (impl->gif == nullptr) {
    return absl::InternalError(absl::StrCat("GIF encoding: ", GifErrorString(error)));
  }
  EGifSetGifVersion(impl->gif, true);
  GifColorType colors[kPaletteSize] = {};
  for (size_t i = 0; i < impl->palette.size(); ++i) {
    colors[i] = {impl->palette[i].r, impl->palette[i].g, impl->palette[i].b};
  }
  ColorMapObject* map = GifMakeMapObject(kPaletteSize, colors);
  const int put = EGifPutScreenDesc(impl->gif, width, height, 8, 0, map);
  GifFreeMapObject(map);
  if (put == GIF_ERROR) return impl->Error("screen descriptor");
  const int loops = std::clamp(impl->options.loop_count, 0, 65535);
  const GifByteType netscape[] = "NETSCAPE2.0";
  const GifByteType loop_block[3] = {1, static_cast<GifByteType>(loops & 0xff),
                                     static_cast<GifByteType>(loops >> 8)};
  if (EGifPutExtensionLeader(impl->gif, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
      EGifPutExtensionBlock(impl->gif, 11, netscape) == GIF_ERROR ||
      EGifPutExtensionBlock(impl->gif, 3, loop_block) == GIF_ERROR ||
      EGifPutExtensionTrailer(impl->gif) == GIF_ERROR) {
    return impl->Error("loop extension");
  }
  return GifEncoder(std::move(impl));
}

absl::Status GifEncoder::AddFrame(const RgbaImage& image) {
  Impl& s = *impl_;
  if (s.gif == nullptr) return absl::FailedPreconditionError("GIF encoder already finished");
  if (image.width != s.width || image.height != s.height) {
    return absl::InvalidArgumentError(absl::StrCat("GIF frame is ", image.width, " x ",
                                                   image.height, ", the animation is ", s.width,
                                                   " x ", s.height));
  }
  std::vector<uint8_t> indices(static_cast<size_t>(s.width) * s.height);
  for (size_t i = 0; i < indices.size(); ++i) indices[i] = s.Index(&image.rgba[4 * i]);

  // The rectangle to store: everything for the first or a transparent frame, else what changed.
  int x0 = 0, y0 = 0, x1 = s.width, y1 = s.height;
  if (!s.options.transparent && !s.previous.empty()) {
    x0 = s.width, y0 = s.height, x1 = 0, y1 = 0;
    for (int y = 0; y < s.height; ++y) {
      for (int x = 0; x < s.width; ++x) {
        const size_t i = static_cast<size_t>(y) * s.width + x;
        if (indices[i] != s.previous[i]) {
          x0 = std::min(x0, x), x1 = std::max(x1, x + 1);
          y0 = std::min(y0, y), y1 = std::max(y1, y + 1);
        }
      }
    }
    if (x1 <= x0) x0 = 0, y0 = 0, x1 = 1, y1 = 1;  // unchanged: a 1-pixel frame keeps the delay
  }

  GraphicsControlBlock gcb{};
  gcb.DisposalMode = s.options.transparent ? DISPOSE_BACKGROUND : DISPOSE_DO_NOT;
  gcb.UserInputFlag = false;
  gcb.DelayTime = GifDelayCentiseconds(s.frames, s.options.fps);
  gcb.TransparentColor = s.options.transparent ? 0 : NO_TRANSPARENT_COLOR;
  GifByteType extension[4];
  const size_t length = EGifGCBToExtension(&gcb, extension);
  if (EGifPutExtension(s.gif, GRAPHICS_EXT_FUNC_CODE, static_cast<int>(length), extension) ==
      GIF_ERROR) {
    return s.Error("graphics control");
  }
  if (EGifPutImageDesc(s.gif, x0, y0, x1 - x0, y1 - y0, false, nullptr) == GIF_ERROR) {
    return s.Error("image descriptor");
  }
  for (int y = y0; y < y1; ++y) {
    if (EGifPutLine(s.gif, &indices[static_cast<size_t>(y) * s.width + x0], x1 - x0) == GIF_ERROR) {
      return s.Error("image data");
    }
  }
  s.previous = std::move(indices);
  ++s.frames;
  return absl::OkStatus();
}

absl::StatusOr<std::string> GifEncoder::Finish() {
  Impl& s = *impl_;
  if (s.gif == nullptr) return absl::FailedPreconditionError("GIF encoder already finished");
  if (s.frames == 0) return absl::FailedPreconditionError("GIF has no frames");
  int error = 0;
  const int closed = EGifCloseFile(s.gif, &error);
  s.gif = nullptr;
  if (closed == GIF_ERROR) {
    return absl::InternalError(absl::StrCat("GIF encoding: ", GifErrorString(error)));
  }
  return std::move(s.bytes);
}

}  // namespace inbetween::render
