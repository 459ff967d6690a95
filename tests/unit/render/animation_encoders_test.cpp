// Tests client/render/gif_encoder.cpp and webp_encoder.cpp: the files decode back (giflib
// DGifSlurp, libwebp WebPAnimDecoder) with the right frame count, size, timing, looping and
// colours.
#include <gif_lib.h>
#include <gtest/gtest.h>
#include <webp/demux.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "client/render/gif_encoder.h"
#include "client/render/raster.h"
#include "client/render/webp_encoder.h"
#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

constexpr Rgba8 kFill = {0x3b, 0x7d, 0xd8, 255};

std::vector<RgbaImage> RenderAll(const FrameSet& set, RasterOptions options) {
  absl::StatusOr<FrameRasterizer> r = FrameRasterizer::Create(set, std::move(options));
  EXPECT_TRUE(r.ok()) << r.status();
  std::vector<RgbaImage> images;
  for (size_t f = 0; f < set.frames.size(); ++f) images.push_back(r->Render(f));
  return images;
}

std::filesystem::path WriteTemp(const std::string& name, const std::string& bytes) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

struct GifCloser {
  void operator()(GifFileType* g) const { DGifCloseFile(g, nullptr); }
};

TEST(GifEncoderTest, DelaysKeepTheAverageFrameRate) {
  int total = 0;
  for (int f = 0; f < 24; ++f) total += GifDelayCentiseconds(f, 24);
  EXPECT_EQ(total, 100);
  EXPECT_EQ(GifDelayCentiseconds(0, 10), 10);
  EXPECT_EQ(GifDelayCentiseconds(5, 100), 2);  // clamped: browsers slow 1 cs down
}

TEST(GifEncoderTest, PaletteRampsBetweenTheAnimationColours) {
  const std::vector<Rgba8> palette =
      GifPalette({.transparent = true, .palette_colors = {{255, 255, 255, 255}, kFill}});
  ASSERT_LE(palette.size(), 256u);
  EXPECT_EQ(palette[0].a, 0);
  EXPECT_EQ(palette[1], (Rgba8{255, 255, 255, 255}));
  EXPECT_EQ(palette[2], kFill);
  EXPECT_GT(palette.size(), 200u);         // a fine ramp for anti-aliased edges
  EXPECT_EQ(GifPalette({}).size(), 252u);  // generic colour cube
}

TEST(GifEncoderTest, DecodesBackWithFrameCountSizeLoopAndColours) {
  const FrameSet set = testing::MorphingRing(12);
  const std::vector<RgbaImage> images = RenderAll(set, {.width = 160});
  absl::StatusOr<GifEncoder> encoder =
      GifEncoder::Create(images[0].width, images[0].height,
                         {.fps = 12, .palette_colors = {{255, 255, 255, 255}, kFill}});
  ASSERT_TRUE(encoder.ok()) << encoder.status();
  for (const RgbaImage& image : images) ASSERT_TRUE(encoder->AddFrame(image).ok());
  EXPECT_FALSE(encoder->AddFrame(RgbaImage(3, 3)).ok());
  absl::StatusOr<std::string> bytes = encoder->Finish();
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  EXPECT_EQ(bytes->substr(0, 6), "GIF89a");
  EXPECT_NE(bytes->find("NETSCAPE2.0"), std::string::npos);

  const auto path = WriteTemp("inbetween_gif_test.gif", *bytes);
  int error = 0;
  std::unique_ptr<GifFileType, GifCloser> gif(DGifOpenFileName(path.c_str(), &error));
  ASSERT_NE(gif, nullptr) << GifErrorString(error);
  ASSERT_EQ(DGifSlurp(gif.get()), GIF_OK) << GifErrorString(gif->Error);
  EXPECT_EQ(gif->ImageCount, 12);
  EXPECT_EQ(gif->SWidth, images[0].width);
  EXPECT_EQ(gif->SHeight, images[0].height);
  GraphicsControlBlock gcb;
  ASSERT_EQ(DGifSavedExtensionToGCB(gif.get(), 3, &gcb), GIF_OK);
  EXPECT_EQ(gcb.DelayTime, GifDelayCentiseconds(3, 12));

  // Compose the frames (each stores the changed rectangle) and compare with the last image.
  std::vector<uint8_t> canvas(static_cast<size_t>(gif->SWidth) * gif->SHeight);
  for (int i = 0; i < gif->ImageCount; ++i) {
    const SavedImage& frame = gif->SavedImages[i];
    const GifImageDesc& d = frame.ImageDesc;
    for (int y = 0; y < d.Height; ++y) {
      std::memcpy(&canvas[static_cast<size_t>(d.Top + y) * gif->SWidth + d.Left],
                  &frame.RasterBits[static_cast<size_t>(y) * d.Width], d.Width);
    }
  }
  const ColorMapObject* map = gif->SColorMap;
  int max_error = 0;
  for (size_t i = 0; i < canvas.size(); ++i) {
    const GifColorType c = map->Colors[canvas[i]];
    const uint8_t* want = &images.back().rgba[4 * i];
    max_error = std::max({max_error, std::abs(c.Red - want[0]), std::abs(c.Green - want[1]),
                          std::abs(c.Blue - want[2])});
  }
  EXPECT_LE(max_error, 4);  // the ramp palette covers the anti-aliased mixes closely
  std::filesystem::remove(path);
}

TEST(GifEncoderTest, TransparentFramesUseIndexZero) {
  const FrameSet set = testing::SquareWithHole();
  const std::vector<RgbaImage> images = RenderAll(set, {.width = 50, .transparent = true});
  absl::StatusOr<GifEncoder> encoder =
      GifEncoder::Create(50, 50, {.transparent = true, .palette_colors = {kFill}});
  ASSERT_TRUE(encoder.ok());
  ASSERT_TRUE(encoder->AddFrame(images[0]).ok());
  absl::StatusOr<std::string> bytes = encoder->Finish();
  ASSERT_TRUE(bytes.ok());
  const auto path = WriteTemp("inbetween_gif_transparent_test.gif", *bytes);
  int error = 0;
  std::unique_ptr<GifFileType, GifCloser> gif(DGifOpenFileName(path.c_str(), &error));
  ASSERT_NE(gif, nullptr);
  ASSERT_EQ(DGifSlurp(gif.get()), GIF_OK);
  GraphicsControlBlock gcb;
  ASSERT_EQ(DGifSavedExtensionToGCB(gif.get(), 0, &gcb), GIF_OK);
  EXPECT_EQ(gcb.TransparentColor, 0);
  EXPECT_EQ(gif->SavedImages[0].RasterBits[0], 0);             // corner: transparent
  EXPECT_EQ(gif->SavedImages[0].RasterBits[25 * 50 + 25], 0);  // the hole
  EXPECT_NE(gif->SavedImages[0].RasterBits[25 * 50 + 6], 0);   // the ring
  std::filesystem::remove(path);
}

TEST(GifEncoderTest, RejectsBadArguments) {
  EXPECT_FALSE(GifEncoder::Create(0, 10).ok());
  EXPECT_FALSE(GifEncoder::Create(10, 10, {.fps = 0}).ok());
  absl::StatusOr<GifEncoder> encoder = GifEncoder::Create(10, 10);
  ASSERT_TRUE(encoder.ok());
  EXPECT_FALSE(encoder->Finish().ok());  // no frames
}

struct WebpDecoderCloser {
  void operator()(WebPAnimDecoder* d) const { WebPAnimDecoderDelete(d); }
};

TEST(WebpEncoderTest, DecodesBackWithFrameCountSizeAndExactPixels) {
  const FrameSet set = testing::MorphingRing(10);
  const std::vector<RgbaImage> images = RenderAll(set, {.width = 128, .transparent = true});
  absl::StatusOr<WebpEncoder> encoder =
      WebpEncoder::Create(images[0].width, images[0].height, {.fps = 10});
  ASSERT_TRUE(encoder.ok()) << encoder.status();
  for (const RgbaImage& image : images) ASSERT_TRUE(encoder->AddFrame(image).ok());
  absl::StatusOr<std::string> bytes = encoder->Finish();
  ASSERT_TRUE(bytes.ok()) << bytes.status();

  WebPData data = {reinterpret_cast<const uint8_t*>(bytes->data()), bytes->size()};
  WebPAnimDecoderOptions options;
  ASSERT_TRUE(WebPAnimDecoderOptionsInit(&options));
  options.color_mode = MODE_RGBA;
  std::unique_ptr<WebPAnimDecoder, WebpDecoderCloser> decoder(WebPAnimDecoderNew(&data, &options));
  ASSERT_NE(decoder, nullptr);
  WebPAnimInfo info;
  ASSERT_TRUE(WebPAnimDecoderGetInfo(decoder.get(), &info));
  EXPECT_EQ(info.canvas_width, static_cast<uint32_t>(images[0].width));
  EXPECT_EQ(info.canvas_height, static_cast<uint32_t>(images[0].height));
  EXPECT_EQ(info.frame_count, 10u);
  EXPECT_EQ(info.loop_count, 0u);
  int frames = 0;
  while (WebPAnimDecoderHasMoreFrames(decoder.get())) {
    uint8_t* rgba = nullptr;
    int timestamp = 0;
    ASSERT_TRUE(WebPAnimDecoderGetNext(decoder.get(), &rgba, &timestamp));
    ++frames;
    EXPECT_EQ(timestamp, 100 * frames);  // end time of the frame at 10 fps
    // Lossless: the opaque pixels come back exactly (transparent ones may lose their colour).
    const RgbaImage& want = images[frames - 1];
    int mismatches = 0;
    for (size_t i = 0; i < want.rgba.size(); i += 4) {
      if (want.rgba[i + 3] == 255) mismatches += std::memcmp(&want.rgba[i], rgba + i, 4) != 0;
      if (want.rgba[i + 3] == 0) mismatches += rgba[i + 3] != 0;
    }
    EXPECT_EQ(mismatches, 0) << "frame " << frames - 1;
  }
  EXPECT_EQ(frames, 10);
}

TEST(WebpEncoderTest, LossyQualityIsSmallerAndStillDecodes) {
  const FrameSet set = testing::MorphingRing(4);
  const std::vector<RgbaImage> images = RenderAll(set, {.width = 128});
  absl::StatusOr<WebpEncoder> encoder =
      WebpEncoder::Create(128, images[0].height, {.lossless = false, .quality = 50});
  ASSERT_TRUE(encoder.ok());
  for (const RgbaImage& image : images) ASSERT_TRUE(encoder->AddFrame(image).ok());
  absl::StatusOr<std::string> bytes = encoder->Finish();
  ASSERT_TRUE(bytes.ok());
  WebPData data = {reinterpret_cast<const uint8_t*>(bytes->data()), bytes->size()};
  std::unique_ptr<WebPAnimDecoder, WebpDecoderCloser> decoder(WebPAnimDecoderNew(&data, nullptr));
  ASSERT_NE(decoder, nullptr);
  WebPAnimInfo info;
  ASSERT_TRUE(WebPAnimDecoderGetInfo(decoder.get(), &info));
  EXPECT_EQ(info.frame_count, 4u);
  EXPECT_FALSE(WebpEncoder::Create(10, 10, {.quality = 101}).ok());
  EXPECT_FALSE(WebpEncoder::Create(10, 10, {.fps = -1}).ok());
}

}  // namespace
}  // namespace inbetween::render
