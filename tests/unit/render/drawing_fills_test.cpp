// Tests the key drawings' fill colours through client/render: FrameFill blending, the optional
// frames.json "fills" field, and their use by the SVG, raster, Lottie and export paths (and that
// an explicit colour wins when drawing_fills is off).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "client/render/export.h"
#include "client/render/frame_set.h"
#include "client/render/lottie_export.h"
#include "client/render/raster.h"
#include "client/render/svg_frames.h"
#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

constexpr Rgba8 kRed = {255, 0, 0, 255};
constexpr Rgba8 kBlue = {0, 0, 255, 255};

FrameSet RedToBlue(int count) {
  FrameSet set = testing::MorphingRing(count);
  set.fills = {kRed, kBlue};
  return set;
}

// The colour of the pixel at the centre of the ring's band in frame f (inside the shape).
Rgba8 BandPixel(const FrameRasterizer& r, const FrameSet& set, size_t f) {
  const Vertex& outer = set.frames[f].vertices[0];
  const Vertex& inner = set.frames[f].vertices[24];
  const auto [x, y] = r.viewport().ToPixels({(outer[0] + inner[0]) / 2, (outer[1] + inner[1]) / 2});
  return r.Render(f).Pixel(static_cast<int>(x), static_cast<int>(y));
}

TEST(DrawingFillsTest, FrameFillBlendsByWeights) {
  const FrameSet set = RedToBlue(5);
  EXPECT_EQ(FrameFill(set, 0), kRed);
  EXPECT_EQ(FrameFill(set, 4), kBlue);
  const Rgba8 mid = *FrameFill(set, 2);  // weights 0.5 / 0.5
  EXPECT_EQ(mid.r, 128);
  EXPECT_EQ(mid.g, 0);
  EXPECT_EQ(mid.b, 128);
  EXPECT_FALSE(FrameFill(testing::MorphingRing(3), 0).has_value());
}

TEST(DrawingFillsTest, FrameFillClampsExtrapolatingWeights) {
  FrameSet set = RedToBlue(3);
  set.frames[1].weights = {1.25, -0.25};  // Catmull-Rom weights can leave [0, 1]
  EXPECT_EQ(FrameFill(set, 1), (Rgba8{255, 0, 0, 255}));
}

TEST(DrawingFillsTest, FramesJsonRoundTripsFillsAndStaysOptional) {
  const FrameSet set = RedToBlue(3);
  const nlohmann::json doc = FrameSetToJson(set);
  ASSERT_TRUE(doc.contains("fills"));
  EXPECT_EQ(doc["fills"], nlohmann::json::array({"#ff0000", "#0000ff"}));
  auto back = FrameSetFromJson(doc);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->fills, set.fills);
  EXPECT_FALSE(FrameSetToJson(testing::MorphingRing(3)).contains("fills"));
}

TEST(DrawingFillsTest, BadFillsInFramesJsonNameThePath) {
  nlohmann::json doc = FrameSetToJson(RedToBlue(3));
  doc["fills"][1] = "bluish";
  auto back = FrameSetFromJson(doc);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("fills[1]"), std::string::npos) << back.status();
  doc["fills"] = 3;
  EXPECT_FALSE(FrameSetFromJson(doc).ok());
}

TEST(DrawingFillsTest, SvgFramesUseTheBlendedFillUnlessTurnedOff) {
  const FrameSet set = RedToBlue(3);
  EXPECT_NE(FrameSvg(set, 0).find("fill=\"#ff0000\""), std::string::npos);
  EXPECT_NE(FrameSvg(set, 2).find("fill=\"#0000ff\""), std::string::npos);
  EXPECT_NE(FrameSvg(set, 1).find("fill=\"#800080\""), std::string::npos);
  const std::string own = FrameSvg(set, 0, {.fill = "#00ff00", .drawing_fills = false});
  EXPECT_NE(own.find("fill=\"#00ff00\""), std::string::npos);
  EXPECT_EQ(own.find("#ff0000"), std::string::npos);
}

TEST(DrawingFillsTest, RasterFillsEachFrameWithItsColour) {
  const FrameSet set = RedToBlue(3);
  auto r = FrameRasterizer::Create(set, {.width = 200});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(BandPixel(*r, set, 0), kRed);
  EXPECT_EQ(BandPixel(*r, set, 2), kBlue);
  auto fixed =
      FrameRasterizer::Create(set, {.width = 200, .fill = "#00ff00", .drawing_fills = false});
  ASSERT_TRUE(fixed.ok());
  EXPECT_EQ(BandPixel(*fixed, set, 2), (Rgba8{0, 255, 0, 255}));
}

TEST(DrawingFillsTest, LottieAnimatesTheColourOnlyWhenItChanges) {
  auto doc = LottieAnimation(RedToBlue(4));
  ASSERT_TRUE(doc.ok()) << doc.status();
  const nlohmann::json& items = (*doc)["layers"][0]["shapes"][0]["it"];
  const nlohmann::json* fill = nullptr;
  for (const auto& item : items) {
    if (item["ty"] == "fl") fill = &item;
  }
  ASSERT_NE(fill, nullptr);
  EXPECT_EQ((*fill)["c"]["a"], 1);
  ASSERT_EQ((*fill)["c"]["k"].size(), 4u);
  EXPECT_EQ((*fill)["c"]["k"][0]["s"], nlohmann::json::array({1.0, 0.0, 0.0, 1}));
  EXPECT_EQ((*fill)["c"]["k"][3]["s"], nlohmann::json::array({0.0, 0.0, 1.0, 1}));

  FrameSet same = RedToBlue(4);
  same.fills = {kBlue, kBlue};
  auto static_doc = LottieAnimation(same);
  ASSERT_TRUE(static_doc.ok());
  for (const auto& item : (*static_doc)["layers"][0]["shapes"][0]["it"]) {
    if (item["ty"] == "fl") {
      EXPECT_EQ(item["c"]["a"], 0);
      EXPECT_EQ(item["c"]["k"], nlohmann::json::array({0.0, 0.0, 1.0, 1}));
    }
  }
}

TEST(DrawingFillsTest, ExportWritesFillsIntoFramesJsonAndSvg) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("drawing_fills_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(ExportFrames(RedToBlue(3), {.dir = dir, .formats = {"json", "svg", "gif"}}).ok());
  std::ifstream json_in(dir / "frames.json");
  const nlohmann::json doc = nlohmann::json::parse(json_in);
  EXPECT_EQ(doc["fills"], nlohmann::json::array({"#ff0000", "#0000ff"}));
  std::ifstream svg_in(dir / "frame_0002.svg");
  std::stringstream svg;
  svg << svg_in.rdbuf();
  EXPECT_NE(svg.str().find("fill=\"#0000ff\""), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "animation.gif"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace inbetween::render
