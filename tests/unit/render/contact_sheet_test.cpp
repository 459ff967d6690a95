// Tests client/render/contact_sheet.cpp: frame choice (keys + evenly spaced inbetweens), sheet
// size, written PNG.
#include "client/render/contact_sheet.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "client/render/png_io.h"
#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

TEST(ContactSheetTest, ShowsEveryKeyAndEvenlySpacedInbetweens) {
  FrameSet set = testing::MorphingRing(24);
  set.keys = {0, 11, 23};
  EXPECT_EQ(ContactSheetFrames(set, 4), (std::vector<size_t>{0, 5, 9, 11, 14, 18, 23}));
  EXPECT_EQ(ContactSheetFrames(set, 0), (std::vector<size_t>{0, 11, 23}));
  set.keys = {0, 99};  // a key naming no frame is skipped
  EXPECT_EQ(ContactSheetFrames(set, 1), (std::vector<size_t>{0, 12}));
  // More inbetweens than frames: each frame once.
  EXPECT_EQ(ContactSheetFrames(testing::MorphingRing(3), 10), (std::vector<size_t>{0, 1, 2}));
}

TEST(ContactSheetTest, WritesAGridOfTheExpectedSize) {
  const FrameSet set = testing::MorphingRing(24);  // 2 keys + 6 inbetweens = 8 cells
  const ContactSheetOptions options = {.cell_width = 100, .columns = 3, .inbetweens = 6};
  absl::StatusOr<FrameRasterizer> cell = FrameRasterizer::Create(set, {.width = 100});
  ASSERT_TRUE(cell.ok());
  const auto path = std::filesystem::temp_directory_path() / "inbetween_contact_sheet_test.png";
  ASSERT_TRUE(WriteContactSheet(path, set, options).ok());
  absl::StatusOr<RgbaImage> sheet = ReadPng(path);
  ASSERT_TRUE(sheet.ok()) << sheet.status();
  EXPECT_EQ(sheet->width, 3 * 100);
  EXPECT_EQ(sheet->height, 3 * (cell->height() + kContactSheetLabelHeight));
  // The first cell shows frame 0 as the rasterizer draws it.
  const RgbaImage first = cell->Render(0);
  const auto [x, y] = cell->viewport().ToPixels(set.frames[0].vertices[0]);
  EXPECT_EQ(sheet->Pixel(static_cast<int>(x) - 3, static_cast<int>(y)),
            first.Pixel(static_cast<int>(x) - 3, static_cast<int>(y)));
  std::filesystem::remove(path);
  EXPECT_FALSE(RenderContactSheet(set, {.columns = 0}).ok());
}

}  // namespace
}  // namespace inbetween::render

// Fontconfig, behind cairo's text on the sheet, keeps process-wide caches until exit that
// LeakSanitizer reports in INBETWEEN_ASAN builds; they are not leaks of ours.
extern "C" const char* __lsan_default_suppressions() { return "leak:libfontconfig\n"; }
