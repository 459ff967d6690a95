// Tests client/frames_output.cpp and the CLI's exit-code mapping.
#include "client/frames_output.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "client/commands.h"
#include "client/render/export.h"

namespace inbetween::client {
namespace {

FramesResult TwoFrames() {
  FramesResult r;
  auto* t = r.header.add_triangles();
  t->set_a(0);
  t->set_b(1);
  t->set_c(2);
  r.header.add_keys(0);
  r.header.add_keys(1);
  r.header.set_frames(2);
  for (int i = 0; i < 2; ++i) {
    v1::InbetweenFrame f;
    f.set_index(i);
    f.set_time(i);
    f.add_weights(1.0 - i);
    f.add_weights(i);
    for (auto [x, y] : {std::pair{0.0, 0.0}, {1.0 + i, 0.0}, {0.0, 1.0}}) {
      auto* p = f.add_vertices();
      p->set_x(x);
      p->set_y(y);
    }
    r.frames.push_back(f);
  }
  return r;
}

TEST(FramesOutputTest, JsonHasTheDocumentedShape) {
  nlohmann::json j = render::FrameSetToJson(ToFrameSet(TwoFrames()));
  EXPECT_EQ(j["triangles"], nlohmann::json::parse("[[0,1,2]]"));
  EXPECT_EQ(j["keys"], nlohmann::json::parse("[0,1]"));
  ASSERT_EQ(j["frames"].size(), 2u);
  EXPECT_EQ(j["frames"][1]["index"], 1);
  EXPECT_DOUBLE_EQ(j["frames"][1]["time"].get<double>(), 1.0);
  EXPECT_EQ(j["frames"][1]["vertices"][1], nlohmann::json::parse("[2.0, 0.0]"));
  EXPECT_EQ(j["frames"][0]["weights"], nlohmann::json::parse("[1.0, 0.0]"));
}

// One art layer per key: a closed triangle path at the mesh's corners.
void AddArt(FramesResult* r) {
  for (uint32_t key : {0u, 1u}) {
    v1::KeyArt* art = r->header.add_art();
    art->set_key(key);
    v1::EmbeddedArtLayer* layer = art->add_layers();
    layer->mutable_paint()->set_id(key == 0 ? "a" : "b");
    layer->mutable_paint()->mutable_fill()->set_rgb(0xff0000);
    layer->mutable_paint()->mutable_fill()->set_opacity(1);
    layer->mutable_paint()->set_opacity(1);
    v1::EmbeddedArtPath* path = layer->add_paths();
    path->set_closed(true);
    for (int corner = 0; corner < 3; ++corner) {
      path->add_triangles(0);
      for (int c = 0; c < 3; ++c) path->add_barycentric(c == corner ? 1.0 : 0.0);
    }
  }
}

TEST(FramesOutputTest, HeaderArtGoesIntoTheFrameSet) {
  FramesResult r = TwoFrames();
  render::FrameSet frames = ToFrameSet(r);
  ASSERT_TRUE(AddHeaderArt(r.header, &frames).ok());
  EXPECT_TRUE(frames.art.empty());  // no art in the header: none

  AddArt(&r);
  ASSERT_TRUE(AddHeaderArt(r.header, &frames).ok());
  ASSERT_EQ(frames.art.size(), 2u);
  EXPECT_EQ(frames.art[1].key, 1);
  EXPECT_EQ(frames.art[1].num_vertices, 3);
  EXPECT_EQ(frames.art[1].layers[0].paint.id, "b");
  EXPECT_EQ(frames.art[1].layers[0].paths[0].points[2].corners, (solver::Triangle{0, 1, 2}));
  EXPECT_EQ(render::FrameSetToJson(frames)["art"].size(), 2u);

  r.header.mutable_art(1)->mutable_layers(0)->mutable_paths(0)->set_triangles(1, 4);
  const absl::Status bad = AddHeaderArt(r.header, &frames);
  EXPECT_EQ(bad.message(), "header.art[1].layers[0].paths[0].triangles[1] refers to triangle 4 of 1");
  EXPECT_TRUE(frames.art.empty());
}

TEST(FramesOutputTest, WritesOneSvgPerFrameAndTheJson) {
  const auto dir = std::filesystem::temp_directory_path() / "inbetween_frames_output_test";
  std::filesystem::remove_all(dir);
  render::ExportOptions options;
  options.dir = dir;
  options.formats = {"svg", "json"};
  options.mesh_overlay = true;
  ASSERT_TRUE(render::ExportFrames(ToFrameSet(TwoFrames()), options).ok());
  EXPECT_TRUE(std::filesystem::exists(dir / "frame_0000.svg"));
  EXPECT_TRUE(std::filesystem::exists(dir / "frame_0001.svg"));
  std::ifstream in(dir / "frames.json");
  EXPECT_EQ(nlohmann::json::parse(in)["frames"].size(), 2u);
  std::ifstream svg(dir / "frame_0001.svg");
  std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("viewBox"), std::string::npos);
  EXPECT_NE(text.find("M0 0L2 0L0 1Z"), std::string::npos) << text;
  std::filesystem::remove_all(dir);
}

TEST(FramesOutputTest, ReportsAnUnwritableDirectory) {
  render::ExportOptions options;
  options.dir = "/proc/definitely/not/here";
  EXPECT_FALSE(render::ExportFrames(ToFrameSet(TwoFrames()), options).ok());
}

TEST(AnimateCommandTest, ExitCodesAreDocumentedOnes) {
  EXPECT_EQ(ExitCodeFor(absl::OkStatus()), 0);
  EXPECT_EQ(ExitCodeFor(absl::InvalidArgumentError("x")), 3);
  EXPECT_EQ(ExitCodeFor(absl::UnavailableError("x")), 4);
  EXPECT_EQ(ExitCodeFor(absl::InternalError("x")), 5);
  EXPECT_EQ(ExitCodeFor(absl::UnimplementedError("x")), 5);
  EXPECT_EQ(ExitCodeFor(absl::CancelledError("x")), 130);
}

}  // namespace
}  // namespace inbetween::client
