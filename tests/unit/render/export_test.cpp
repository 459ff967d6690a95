// Tests client/render/export.cpp: every format lands under its documented name with the right
// size, unknown formats and bad options fail and write nothing, progress is reported.
#include "client/render/export.h"

#include <gif_lib.h>
#include <gtest/gtest.h>
#include <webp/demux.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "absl/strings/str_format.h"
#include "client/render/contact_sheet.h"
#include "client/render/png_io.h"
#include "client/render/raster.h"
#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

namespace fs = std::filesystem;

class ExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("inbetween_export_test_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::set<std::string> Files() const {
    std::set<std::string> names;
    if (!fs::exists(dir_)) return names;
    for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
    return names;
  }

  fs::path dir_;
};

TEST_F(ExportTest, ParseFormatsAcceptsAListAndNamesTheUnknownOne) {
  absl::StatusOr<std::vector<std::string>> f = ParseFormats(" svg, GIF ,json,gif");
  ASSERT_TRUE(f.ok()) << f.status();
  EXPECT_EQ(*f, (std::vector<std::string>{"svg", "gif", "json"}));
  f = ParseFormats("svg,mp4");
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(f.status().message().find("\"mp4\""), std::string::npos);
  EXPECT_NE(f.status().message().find("svg, json, png, gif, webp, lottie, contact"),
            std::string::npos)
      << f.status();
  EXPECT_FALSE(ParseFormats("").ok());
}

TEST_F(ExportTest, WritesEveryFormatUnderItsDocumentedName) {
  const FrameSet set = testing::MorphingRing(6);
  std::vector<std::string> stages;
  ExportReport report;
  const absl::Status s =
      ExportFrames(set,
                   {.dir = dir_,
                    .formats = {"svg", "json", "png", "gif", "webp", "lottie", "contact"},
                    .width = 120,
                    .fps = 12,
                    .progress =
                        [&](std::string_view stage, int done, int total) {
                          if (done == total) stages.emplace_back(stage);
                        }},
                   &report);
  ASSERT_TRUE(s.ok()) << s;
  std::set<std::string> want = {"frames.json", "animation.gif", "animation.webp",
                                "animation.lottie.json", "contact_sheet.png"};
  for (int f = 0; f < 6; ++f) {
    want.insert(absl::StrFormat("frame_%04d.svg", f));
    want.insert(absl::StrFormat("frame_%04d.png", f));
  }
  EXPECT_EQ(Files(), want);  // and no staging folder left behind
  EXPECT_EQ(report.files.size(), want.size());
  EXPECT_GT(report.bytes, 0u);
  EXPECT_EQ(stages, (std::vector<std::string>{"json", "svg", "frames", "gif", "webp", "lottie",
                                              "contact"}));

  // Sizes: PNG frames at the requested width; the GIF and WebP decode to the same.
  absl::StatusOr<RgbaImage> png = ReadPng(dir_ / "frame_0003.png");
  ASSERT_TRUE(png.ok());
  EXPECT_EQ(png->width, 120);
  int error = 0;
  GifFileType* gif = DGifOpenFileName((dir_ / "animation.gif").c_str(), &error);
  ASSERT_NE(gif, nullptr);
  ASSERT_EQ(DGifSlurp(gif), GIF_OK);
  EXPECT_EQ(gif->ImageCount, 6);
  EXPECT_EQ(gif->SWidth, png->width);
  EXPECT_EQ(gif->SHeight, png->height);
  DGifCloseFile(gif, &error);
  std::ifstream webp_in(dir_ / "animation.webp", std::ios::binary);
  const std::string webp((std::istreambuf_iterator<char>(webp_in)), {});
  WebPData data = {reinterpret_cast<const uint8_t*>(webp.data()), webp.size()};
  WebPAnimDecoder* decoder = WebPAnimDecoderNew(&data, nullptr);
  ASSERT_NE(decoder, nullptr);
  WebPAnimInfo info;
  ASSERT_TRUE(WebPAnimDecoderGetInfo(decoder, &info));
  EXPECT_EQ(info.frame_count, 6u);
  EXPECT_EQ(info.canvas_width, static_cast<uint32_t>(png->width));
  EXPECT_EQ(info.canvas_height, static_cast<uint32_t>(png->height));
  WebPAnimDecoderDelete(decoder);
  std::ifstream lottie_in(dir_ / "animation.lottie.json");
  const nlohmann::json lottie = nlohmann::json::parse(lottie_in);
  EXPECT_EQ(lottie["op"], 6);
  EXPECT_EQ(lottie["w"], 120);
  std::ifstream json_in(dir_ / "frames.json");
  absl::StatusOr<FrameSet> back = FrameSetFromJson(nlohmann::json::parse(json_in));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->frames.size(), 6u);
  absl::StatusOr<RgbaImage> sheet = ReadPng(dir_ / "contact_sheet.png");
  ASSERT_TRUE(sheet.ok());
  EXPECT_EQ(sheet->width, 4 * 64);  // cells of max(64, width / 2); 6 frames = 4 + 2 cells
}

TEST_F(ExportTest, SingleFrameWorksInEveryFormat) {
  const absl::Status s =
      ExportFrames(testing::SquareWithHole(),
                   {.dir = dir_,
                    .formats = {"svg", "json", "png", "gif", "webp", "lottie", "contact"},
                    .width = 64,
                    .mesh_overlay = true,
                    .transparent = true});
  ASSERT_TRUE(s.ok()) << s;
  EXPECT_EQ(Files().size(), 7u);
  std::ifstream lottie_in(dir_ / "animation.lottie.json");
  EXPECT_EQ(nlohmann::json::parse(lottie_in)["op"], 1);
}

TEST_F(ExportTest, UnknownFormatFailsAndWritesNothing) {
  const absl::Status s =
      ExportFrames(testing::MorphingRing(3), {.dir = dir_, .formats = {"svg", "gif", "avi"}});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("\"avi\""), std::string::npos) << s;
  EXPECT_NE(s.message().find("lottie"), std::string::npos) << s;
  EXPECT_FALSE(fs::exists(dir_));  // not even the directory
}

TEST_F(ExportTest, BadOptionsOrFramesFailAndLeaveAnExistingDirUntouched) {
  fs::create_directories(dir_);
  std::ofstream(dir_ / "keep.txt") << "mine";
  const FrameSet set = testing::MorphingRing(3);
  EXPECT_FALSE(ExportFrames(set, {.dir = dir_, .fill = "bluish"}).ok());
  EXPECT_FALSE(ExportFrames(set, {.dir = dir_, .fps = 0}).ok());
  EXPECT_FALSE(ExportFrames(set, {.dir = dir_, .formats = {"png"}, .width = 0}).ok());
  EXPECT_FALSE(ExportFrames(set, {.dir = dir_, .formats = {}}).ok());
  EXPECT_FALSE(ExportFrames(FrameSet{}, {.dir = dir_}).ok());
  FrameSet flipped = set;  // BoundaryLoops rejects it: found before anything is written
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  const absl::Status s = ExportFrames(flipped, {.dir = dir_, .formats = {"svg", "lottie"}});
  EXPECT_NE(s.message().find("same direction"), std::string::npos) << s;
  EXPECT_EQ(Files(), std::set<std::string>{"keep.txt"});
}

TEST_F(ExportTest, UnwritableDirectoryIsUnavailable) {
  const absl::Status s = ExportFrames(testing::MorphingRing(2), {.dir = "/proc/no/such/dir"});
  EXPECT_EQ(s.code(), absl::StatusCode::kUnavailable) << s;
}

TEST_F(ExportTest, OverwritesAPreviousExport) {
  const FrameSet set = testing::MorphingRing(3);
  ASSERT_TRUE(ExportFrames(set, {.dir = dir_, .formats = {"gif"}, .width = 50}).ok());
  const auto before = fs::file_size(dir_ / "animation.gif");
  ASSERT_TRUE(ExportFrames(set, {.dir = dir_, .formats = {"gif"}, .width = 100}).ok());
  EXPECT_NE(fs::file_size(dir_ / "animation.gif"), before);
  EXPECT_EQ(Files(), std::set<std::string>{"animation.gif"});
}

}  // namespace
}  // namespace inbetween::render
