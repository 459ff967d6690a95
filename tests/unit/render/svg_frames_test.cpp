// Tests client/render/svg_frames.cpp: outline paths (holes as reverse-wound subpaths), shared
// viewBox, mesh overlay, fallback for meshes without clean loops.
#include "client/render/svg_frames.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(SvgFramesTest, FillIsTheOutlineWithOneSubpathPerLoop) {
  const std::string svg = FrameSvg(testing::SquareWithHole(), 0, {.fill = "#ff0000"});
  EXPECT_EQ(Count(svg, "<path"), 1);
  EXPECT_EQ(Count(svg, "M"), 2);  // outside and hole
  EXPECT_NE(svg.find("fill=\"#ff0000\" fill-rule=\"nonzero\""), std::string::npos);
  EXPECT_NE(svg.find("viewBox=\"-0.5 -0.5 11 11\""), std::string::npos) << svg;
}

TEST(SvgFramesTest, SingleTriangleOutlineStartsAtItsFirstVertex) {
  const FrameSet set = testing::OneFrame({{0, 0}, {2, 0}, {0, 1}}, {{0, 1, 2}});
  EXPECT_NE(FrameSvg(set, 0).find("d=\"M0 0L2 0L0 1Z\""), std::string::npos);
}

TEST(SvgFramesTest, MeshOverlayAddsTheTriangles) {
  const std::string svg = FrameSvg(testing::SquareWithHole(), 0, {.mesh_overlay = true});
  EXPECT_EQ(Count(svg, "<path"), 2);
  EXPECT_EQ(Count(svg, "M"), 2 + 8);
}

TEST(SvgFramesTest, MeshWithoutCleanLoopsStillDraws) {
  const FrameSet set = testing::OneFrame({{0, 0}, {1, 0}, {0, 1}, {1, 1}}, {{0, 1, 2}, {0, 1, 3}});
  const std::string svg = FrameSvg(set, 0);
  EXPECT_EQ(Count(svg, "M"), 2);
}

TEST(SvgFramesTest, EveryFrameSharesTheViewBox) {
  const FrameSet set = testing::MorphingRing(3);
  const auto view_box = [](const std::string& svg) {
    const size_t at = svg.find("viewBox");
    return svg.substr(at, svg.find('>', at) - at);
  };
  EXPECT_EQ(view_box(FrameSvg(set, 0)), view_box(FrameSvg(set, 2)));
  const auto dir = std::filesystem::temp_directory_path() / "inbetween_svg_frames_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(WriteSvgFrames(dir, set).ok());
  EXPECT_TRUE(std::filesystem::exists(dir / "frame_0002.svg"));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 3);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace inbetween::render
