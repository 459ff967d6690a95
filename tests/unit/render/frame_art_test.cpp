// Tests the art path of client/render (frame_set.cpp FrameArt/CheckFrameSet, art_json.cpp,
// raster.cpp, svg_frames.cpp): a two-key frame set whose art (a red square under a black
// stroked circle) is embedded in a two-triangle mesh, round-tripped through frames.json and drawn
// by the rasterizer and the SVG writer, or as the silhouette when art is off.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "client/render/raster.h"
#include "client/render/svg_frames.h"
#include "solver/art/art_embedding.h"

namespace inbetween::render {
namespace {

// Key 0: the square [0, 10]^2; key 1: the same moved 20 to the right; frame 1 halfway.
FrameSet MovingSquare() {
  FrameSet set;
  set.triangles = {{0, 1, 2}, {0, 2, 3}};
  set.keys = {0, 2};
  const auto square = [](double dx) {
    return std::vector<Vertex>{{dx, 0}, {dx + 10, 0}, {dx + 10, 10}, {dx, 10}};
  };
  set.frames = {
      {0, 0.0, {1, 0}, square(0)}, {1, 0.5, {0.5, 0.5}, square(10)}, {2, 1.0, {0, 1}, square(20)}};
  return set;
}

// Drawn in key 0's place; `dx` moves it to key 1's.
std::vector<solver::ArtLayer> SquareAndCircle(double dx = 0) {
  solver::ArtLayer square;
  square.paths = {{.points = {{1, 1}, {9, 1}, {9, 9}, {1, 9}}, .closed = true}};
  square.fill = solver::FillPaint{.rgb = 0xff0000};
  solver::ArtLayer circle;
  circle.paths = {{.points = {}, .closed = true}};
  for (int i = 0; i < 64; ++i) {
    const double a = 2 * std::numbers::pi * i / 64;
    circle.paths[0].points.emplace_back(5 + 3 * std::cos(a), 5 + 3 * std::sin(a));
  }
  circle.stroke = solver::StrokePaint{.rgb = 0x000000, .width = 1};
  std::vector<solver::ArtLayer> art = {square, circle};
  for (solver::ArtLayer& layer : art) {
    for (solver::ArtPath& path : layer.paths) {
      for (solver::Point& p : path.points) p.x() += dx;
    }
  }
  return art;
}

// The set with both keys' art (the same drawing) embedded in their shapes.
FrameSet WithArt() {
  FrameSet set = MovingSquare();
  solver::Multimesh mesh;
  for (const auto& t : set.triangles) mesh.triangles.push_back({t[0], t[1], t[2]});
  for (int f : {0, 2}) {
    solver::Points shape;
    for (const Vertex& v : set.frames[f].vertices) shape.emplace_back(v[0], v[1]);
    mesh.shapes.push_back(shape);
  }
  for (int k = 0; k < 2; ++k) {
    absl::StatusOr<solver::EmbeddedArt> art = solver::EmbedArt(mesh, k, SquareAndCircle(20.0 * k));
    EXPECT_TRUE(art.ok()) << art.status();
    set.art.push_back(*std::move(art));
  }
  return set;
}

Rgba8 PixelAt(const FrameRasterizer& r, const RgbaImage& image, Vertex p) {
  const auto [x, y] = r.viewport().ToPixels(p);
  return image.Pixel(static_cast<int>(x), static_cast<int>(y));
}

TEST(FrameArtTest, KeyFramesShowTheKeysArtAndInbetweensFollowTheMesh) {
  const FrameSet set = WithArt();
  ASSERT_TRUE(CheckFrameSet(set).ok()) << CheckFrameSet(set);
  absl::StatusOr<std::vector<solver::ArtLayer>> key = FrameArt(set, 0);
  ASSERT_TRUE(key.ok()) << key.status();
  ASSERT_EQ(key->size(), 2u);
  EXPECT_NEAR((*key)[0].paths[0].points[0].x(), 1.0, 1e-9);
  absl::StatusOr<std::vector<solver::ArtLayer>> mid = FrameArt(set, 1);
  ASSERT_TRUE(mid.ok()) << mid.status();
  EXPECT_NEAR((*mid)[0].paths[0].points[0].x(), 11.0, 1e-9);  // moved with the mesh
}

TEST(FrameArtTest, RasterDrawsTheArtOrTheSilhouette) {
  const FrameSet set = WithArt();
  absl::StatusOr<FrameRasterizer> r = FrameRasterizer::Create(set, {.width = 300});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->draws_art());
  const RgbaImage last = r->Render(2);
  EXPECT_EQ(PixelAt(*r, last, {21.3, 2}), (Rgba8{255, 0, 0, 255}));      // red square
  EXPECT_EQ(PixelAt(*r, last, {28, 5}), (Rgba8{0, 0, 0, 255}));          // the circle's stroke
  EXPECT_EQ(PixelAt(*r, last, {20.3, 5}), (Rgba8{255, 255, 255, 255}));  // mesh, not art
  EXPECT_EQ(PixelAt(*r, last, {5, 5}), (Rgba8{255, 255, 255, 255}));     // key 0's place
  absl::StatusOr<FrameRasterizer> s =
      FrameRasterizer::Create(set, {.width = 300, .fill = "#00ff00", .art = false});
  ASSERT_TRUE(s.ok());
  EXPECT_FALSE(s->draws_art());
  EXPECT_EQ(PixelAt(*s, s->Render(2), {28, 5}), (Rgba8{0, 255, 0, 255}));
}

TEST(FrameArtTest, SvgFramesHoldTheLayersInPaintOrder) {
  const FrameSet set = WithArt();
  const std::string svg = FrameSvg(set, 0);
  const size_t red = svg.find("fill=\"#ff0000\"");
  const size_t black = svg.find("stroke=\"#000000\"");
  ASSERT_NE(red, std::string::npos) << svg;
  ASSERT_NE(black, std::string::npos) << svg;
  EXPECT_LT(red, black);
  EXPECT_EQ(FrameSvg(set, 0, {.art = false}).find("#ff0000"), std::string::npos);
}

TEST(FrameArtTest, FramesJsonRoundTripKeepsTheArt) {
  FrameSet set = WithArt();
  set.art[1].layers[1].paint.stroke->dashes = {2, 1};
  set.art[1].layers[1].paint.stroke->cap = solver::LineCap::kRound;
  set.art[1].layers[0].paint.fill->even_odd = true;
  set.art[1].layers[0].paint.opacity = 0.25;
  const nlohmann::json doc = FrameSetToJson(set);
  ASSERT_TRUE(doc.contains("art"));
  absl::StatusOr<FrameSet> back = FrameSetFromJson(doc);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->art.size(), 2u);
  for (size_t f = 0; f < set.frames.size(); ++f) {
    absl::StatusOr<std::vector<solver::ArtLayer>> a = FrameArt(set, f), b = FrameArt(*back, f);
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_EQ(a->size(), b->size());
    for (size_t l = 0; l < a->size(); ++l) {
      EXPECT_EQ((*a)[l].opacity, (*b)[l].opacity);
      EXPECT_EQ((*a)[l].fill.has_value(), (*b)[l].fill.has_value());
      if ((*a)[l].fill) EXPECT_EQ((*a)[l].fill->even_odd, (*b)[l].fill->even_odd);
      if ((*a)[l].stroke) {
        EXPECT_EQ((*a)[l].stroke->dashes, (*b)[l].stroke->dashes);
        EXPECT_EQ((*a)[l].stroke->cap, (*b)[l].stroke->cap);
      }
      ASSERT_EQ((*a)[l].paths.size(), (*b)[l].paths.size());
      for (size_t p = 0; p < (*a)[l].paths.size(); ++p) {
        ASSERT_EQ((*a)[l].paths[p].points.size(), (*b)[l].paths[p].points.size());
        for (size_t i = 0; i < (*a)[l].paths[p].points.size(); ++i) {
          EXPECT_NEAR(((*a)[l].paths[p].points[i] - (*b)[l].paths[p].points[i]).norm(), 0, 1e-12);
        }
      }
    }
  }
  // An old frames.json (no art) still reads, without art.
  nlohmann::json old = doc;
  old.erase("art");
  absl::StatusOr<FrameSet> plain = FrameSetFromJson(old);
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->art.empty());
}

TEST(FrameArtTest, BadArtIsRejectedWithItsPath) {
  nlohmann::json doc = FrameSetToJson(WithArt());
  doc["art"][0]["layers"][1]["paths"][0]["points"][3][0] = 7;
  absl::StatusOr<FrameSet> bad = FrameSetFromJson(doc);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("art[0].layers[1].paths[0].points[3]"), std::string::npos)
      << bad.status();
  doc = FrameSetToJson(WithArt());
  doc["frames"][1]["weights"] = {0.5};
  bad = FrameSetFromJson(doc);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("frames[1].weights"), std::string::npos) << bad.status();
}

}  // namespace
}  // namespace inbetween::render
