// Tests client/render/art_painter.cpp: a red square with a black stroked circle over it, painted
// anti-aliased, gives red inside the fill, black on the stroke, the background outside; fill
// rules, layer opacity (grouped when a layer has fill and stroke) and dashes.
#include "client/render/art_painter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace inbetween::render {
namespace {

constexpr Rgba8 kWhite = {255, 255, 255, 255};

// 1 user unit = 2 px over [0, 50]^2: a 100 x 100 image.
Viewport TestViewport() {
  return {.scale = 2.0, .origin_x = 0, .origin_y = 0, .width = 100, .height = 100};
}

solver::ArtPath Square(double x0, double y0, double x1, double y1) {
  return {.points = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, .closed = true};
}

solver::ArtPath Circle(double cx, double cy, double r, int n = 128) {
  solver::ArtPath path{.points = {}, .closed = true};
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    path.points.emplace_back(cx + r * std::cos(a), cy + r * std::sin(a));
  }
  return path;
}

// The two-layer art: a red square [5, 45]^2, and over it a black circle of radius 12 around
// (25, 25) stroked 4 units wide, not filled.
std::vector<solver::ArtLayer> SquareAndCircle() {
  solver::ArtLayer square;
  square.paths = {Square(5, 5, 45, 45)};
  square.fill = solver::FillPaint{.rgb = 0xff0000};
  solver::ArtLayer circle;
  circle.paths = {Circle(25, 25, 12)};
  circle.stroke = solver::StrokePaint{.rgb = 0x000000, .width = 4};
  return {square, circle};
}

// The pixel under user point (x, y).
Rgba8 At(const RgbaImage& image, const Viewport& v, double x, double y) {
  const auto [px, py] = v.ToPixels({x, y});
  return image.Pixel(static_cast<int>(px), static_cast<int>(py));
}

TEST(ArtPainterTest, FillStrokeAndBackgroundWhereTheyAreDrawn) {
  const Viewport v = TestViewport();
  const RgbaImage image = RenderArt(SquareAndCircle(), v, kWhite);
  ASSERT_EQ(image.width, 100);
  ASSERT_EQ(image.height, 100);
  const Rgba8 red = {255, 0, 0, 255}, black = {0, 0, 0, 255};
  EXPECT_EQ(At(image, v, 10, 10), red);    // in the square, outside the circle
  EXPECT_EQ(At(image, v, 25, 25), red);    // inside the circle: not filled, the square shows
  EXPECT_EQ(At(image, v, 37, 25), black);  // on the stroke (radius 12, width 4)
  EXPECT_EQ(At(image, v, 25, 13.5), black);
  EXPECT_EQ(At(image, v, 2, 2), kWhite);  // outside everything
  EXPECT_EQ(At(image, v, 48, 25), kWhite);
}

TEST(ArtPainterTest, EdgesAreAntialiased) {
  const Viewport v = TestViewport();
  const RgbaImage image = RenderArt(SquareAndCircle(), v, kWhite);
  // The circle's stroke passes pixels partly: some pixel near it is neither black nor red.
  int mixed = 0;
  for (int x = 0; x < 100; ++x) {
    const Rgba8 c = image.Pixel(x, 37);
    if (c.r > 0 && c.r < 255 && c.g < 200) ++mixed;
  }
  EXPECT_GT(mixed, 0);
}

TEST(ArtPainterTest, FillRulesAndTransparentBackground) {
  // Two nested squares in one layer, both counter-clockwise: nonzero fills the inner one,
  // even-odd leaves it a hole.
  solver::ArtLayer layer;
  layer.paths = {Square(5, 5, 45, 45), Square(15, 15, 35, 35)};
  layer.fill = solver::FillPaint{.rgb = 0x0000ff};
  const Viewport v = TestViewport();
  EXPECT_EQ(At(RenderArt({layer}, v, kWhite), v, 25, 25), (Rgba8{0, 0, 255, 255}));
  layer.fill->even_odd = true;
  const RgbaImage holed = RenderArt({layer}, v, {255, 255, 255, 0});
  EXPECT_EQ(At(holed, v, 25, 25).a, 0);
  EXPECT_EQ(At(holed, v, 10, 10), (Rgba8{0, 0, 255, 255}));
}

TEST(ArtPainterTest, LayerOpacityCompositesFillAndStrokeAsOne) {
  // A half-opaque layer whose black stroke covers its red fill: as a group, the stroke over the
  // fill is grey (black at 50% over white), not a mix with red showing through.
  solver::ArtLayer layer;
  layer.paths = {Square(10, 10, 40, 40)};
  layer.fill = solver::FillPaint{.rgb = 0xff0000};
  layer.stroke = solver::StrokePaint{.rgb = 0x000000, .width = 6};
  layer.opacity = 0.5;
  const Viewport v = TestViewport();
  const RgbaImage image = RenderArt({layer}, v, kWhite);
  const Rgba8 edge = At(image, v, 10.5, 25);  // on the stroke, inside the fill
  EXPECT_NEAR(edge.r, 128, 2);
  EXPECT_NEAR(edge.g, 128, 2);
  const Rgba8 inside = At(image, v, 25, 25);  // fill only: red at 50% over white
  EXPECT_EQ(inside.r, 255);
  EXPECT_NEAR(inside.g, 128, 2);
  // Fill opacity multiplies in: a 50% fill of a fully opaque layer is the same pink.
  solver::ArtLayer fill_only = layer;
  fill_only.stroke.reset();
  fill_only.opacity = 1;
  fill_only.fill->opacity = 0.5;
  EXPECT_NEAR(At(RenderArt({fill_only}, v, kWhite), v, 25, 25).g, 128, 2);
}

TEST(ArtPainterTest, DashesLeaveGapsAndCapsExtendTheLine) {
  // A horizontal line at y = 25 from x = 5 to 45, 2 units wide, dashed 10 on 10 off.
  solver::ArtLayer line;
  line.paths = {{.points = {{5, 25}, {45, 25}}, .closed = false}};
  line.stroke = solver::StrokePaint{.rgb = 0x000000, .width = 2, .dashes = {10, 10}};
  const Viewport v = TestViewport();
  const RgbaImage dashed = RenderArt({line}, v, kWhite);
  EXPECT_EQ(At(dashed, v, 10, 25), (Rgba8{0, 0, 0, 255}));  // first dash [5, 15]
  EXPECT_EQ(At(dashed, v, 20, 25), kWhite);                 // gap [15, 25]
  EXPECT_EQ(At(dashed, v, 30, 25), (Rgba8{0, 0, 0, 255}));  // second dash [25, 35]
  // Butt caps stop at the end; square caps reach half the width beyond it.
  line.stroke->dashes.clear();
  EXPECT_EQ(At(RenderArt({line}, v, kWhite), v, 45.6, 25), kWhite);
  line.stroke->cap = solver::LineCap::kSquare;
  EXPECT_EQ(At(RenderArt({line}, v, kWhite), v, 45.6, 25), (Rgba8{0, 0, 0, 255}));
}

}  // namespace
}  // namespace inbetween::render
