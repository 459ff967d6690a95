// Tests client/render/raster.cpp, viewport.cpp, color.cpp and png_io.cpp: size semantics, the
// shape coloured and holes/outside background, mesh overlay, transparency, PNG round trip.
#include "client/render/raster.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "client/render/png_io.h"
#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

constexpr Rgba8 kWhite = {255, 255, 255, 255};

FrameRasterizer MakeRasterizer(const FrameSet& set, RasterOptions options) {
  absl::StatusOr<FrameRasterizer> r = FrameRasterizer::Create(set, std::move(options));
  EXPECT_TRUE(r.ok()) << r.status();
  return *std::move(r);
}

// The pixel under user-space point p.
Rgba8 PixelAt(const FrameRasterizer& r, const RgbaImage& image, Vertex p) {
  const auto [x, y] = r.viewport().ToPixels(p);
  return image.Pixel(static_cast<int>(x), static_cast<int>(y));
}

TEST(ColorTest, ParsesHexAndNamesAndRejectsTheRest) {
  EXPECT_EQ(*ParseColor("#3b7dd8"), (Rgba8{0x3b, 0x7d, 0xd8, 255}));
  EXPECT_EQ(*ParseColor("#fff"), kWhite);
  EXPECT_EQ(*ParseColor("#00000080"), (Rgba8{0, 0, 0, 128}));
  EXPECT_EQ(*ParseColor("White"), kWhite);
  for (const char* bad : {"", "3b7dd8", "#3b7dd", "#zzzzzz", "mauve"}) {
    absl::StatusOr<Rgba8> c = ParseColor(bad);
    ASSERT_FALSE(c.ok()) << bad;
    EXPECT_NE(c.status().message().find("#rrggbb"), std::string::npos);
  }
  EXPECT_EQ(HexColor({0x3b, 0x7d, 0xd8, 255}), "#3b7dd8");
}

TEST(ViewportTest, WidthIsGivenAndHeightFollowsTheAspectWithMargin) {
  const FrameSet set = testing::TwoSquares();  // bounds 6 x 1, margin 0.3 each side
  absl::StatusOr<Viewport> v = FrameSetViewport(set, 660);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v->width, 660);
  EXPECT_EQ(v->height, 160);  // 660 * 1.6 / 6.6
  EXPECT_NEAR(v->ToPixels({-0.3, -0.3})[0], 0.0, 1e-9);
  EXPECT_NEAR(v->ToPixels({6.3, 1.3})[1], 160.0, 1e-9);
  EXPECT_FALSE(FrameSetViewport(set, 0).ok());
  EXPECT_FALSE(FrameSetViewport(set, kMaxImageSide + 1).ok());
  EXPECT_FALSE(FrameSetViewport(FrameSet{}, 100).ok());
  EXPECT_FALSE(FrameSetViewport(testing::OneFrame({{1, 1}, {1, 1}, {1, 1}}, {}), 100).ok());
}

TEST(ViewportTest, EveryFrameSharesTheSequenceBounds) {
  const FrameSet set = testing::MorphingRing(9);
  FrameRasterizer r = MakeRasterizer(set, {.width = 300});
  for (size_t f = 0; f < set.frames.size(); ++f) {
    const RgbaImage image = r.Render(f);
    EXPECT_EQ(image.width, 300);
    EXPECT_EQ(image.height, r.height());
  }
}

TEST(RasterTest, ShapeIsFilledHoleAndOutsideAreBackground) {
  const FrameSet set = testing::SquareWithHole();
  FrameRasterizer r = MakeRasterizer(set, {.width = 200, .fill = "#3b7dd8"});
  const RgbaImage image = r.Render(0);
  ASSERT_EQ(image.width, 200);
  ASSERT_EQ(image.height, 200);
  EXPECT_EQ(PixelAt(r, image, {1.5, 1.5}), (Rgba8{0x3b, 0x7d, 0xd8, 255}));  // in the ring
  EXPECT_EQ(PixelAt(r, image, {8.5, 5.0}), (Rgba8{0x3b, 0x7d, 0xd8, 255}));
  EXPECT_EQ(PixelAt(r, image, {5.0, 5.0}), kWhite);    // the hole
  EXPECT_EQ(PixelAt(r, image, {-0.4, -0.4}), kWhite);  // the margin
  EXPECT_EQ(image.Pixel(0, 0), kWhite);
  // Anti-aliased: the edge at x = 0 crosses pixel centres, so some pixels are mixed.
  bool mixed = false;
  for (int x = 0; x < image.width; ++x) {
    const Rgba8 p = image.Pixel(x, 100);
    mixed |= p.r != 255 && p.r != 0x3b;
  }
  EXPECT_TRUE(mixed);
}

TEST(RasterTest, TransparentBackgroundAndMeshOverlay) {
  const FrameSet set = testing::SquareWithHole();
  FrameRasterizer plain = MakeRasterizer(set, {.width = 200, .transparent = true});
  const RgbaImage image = plain.Render(0);
  EXPECT_EQ(PixelAt(plain, image, {5.0, 5.0}).a, 0);
  EXPECT_EQ(PixelAt(plain, image, {1.5, 1.5}).a, 255);

  const RgbaImage opaque = MakeRasterizer(set, {.width = 200}).Render(0);
  FrameRasterizer mesh = MakeRasterizer(set, {.width = 200, .mesh_overlay = true});
  const RgbaImage with_mesh = mesh.Render(0);
  ASSERT_EQ(with_mesh.rgba.size(), opaque.rgba.size());
  int darker = 0;  // pixels the overlay lines darken clearly
  for (size_t i = 0; i < opaque.rgba.size(); i += 4) {
    const int before = opaque.rgba[i] + opaque.rgba[i + 1] + opaque.rgba[i + 2];
    const int after = with_mesh.rgba[i] + with_mesh.rgba[i + 1] + with_mesh.rgba[i + 2];
    darker += after < before - 60;
  }
  EXPECT_GT(darker, 400);  // 16 edges, each at least 60 px long
}

TEST(RasterTest, CreateReportsBadOptionsAndMeshes) {
  const FrameSet set = testing::SquareWithHole();
  EXPECT_FALSE(FrameRasterizer::Create(set, {.fill = "teal-ish"}).ok());
  EXPECT_FALSE(FrameRasterizer::Create(set, {.width = -1}).ok());
  FrameSet flipped = set;
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_FALSE(FrameRasterizer::Create(flipped, {}).ok());
}

TEST(PngTest, WritesAndReadsBackTheSameImage) {
  const FrameSet set = testing::SquareWithHole();
  FrameRasterizer r = MakeRasterizer(set, {.width = 120, .transparent = true});
  const RgbaImage image = r.Render(0);
  const auto path = std::filesystem::temp_directory_path() / "inbetween_raster_test.png";
  ASSERT_TRUE(WritePng(path, image).ok());
  absl::StatusOr<RgbaImage> back = ReadPng(path);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->width, 120);
  EXPECT_EQ(back->height, 120);
  // Opaque pixels survive exactly; translucent ones up to premultiplication rounding.
  EXPECT_EQ(PixelAt(r, *back, {1.5, 1.5}), PixelAt(r, image, {1.5, 1.5}));
  EXPECT_EQ(PixelAt(r, *back, {5, 5}).a, 0);
  std::filesystem::remove(path);
  EXPECT_FALSE(ReadPng(path).ok());
  EXPECT_FALSE(WritePng("/proc/not/a/dir/x.png", image).ok());
}

}  // namespace
}  // namespace inbetween::render
