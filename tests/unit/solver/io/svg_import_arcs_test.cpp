// Elliptical arcs (SVG 1.1 F.6): our own endpoint-to-centre conversion. Regression for the
// svg_import_fuzz finding: an arc with a zero radius made SVG++'s converter compute NaN (UB in
// a NaN-to-int conversion) and the drawing was refused; SVG draws it as a straight line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "solver/io/svg_import.h"

namespace inbetween::solver {
namespace {

std::string Svg(const std::string& body) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\">" + body + "</svg>";
}

// The fuzzer's input (build/fuzz/artifacts/svg_import_fuzz/crash-a3f381ce…), verbatim path:
// its second arc has rx = 0 (NaN inside SVG++ before), then a stray number. Now the arc is a
// line and the refusal is about the path data, as it should be.
TEST(SvgImportArcsTest, FuzzerInputIsRefusedForItsPathDataNotForNaN) {
  absl::StatusOr<Drawing> d =
      ImportSvg(Svg("<path d=\"M 10 50 A 40 40 0 1 1 90 5A 0 40 40 0 1 1 10 50 Z\"/>"));
  EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(d.status().message(), ::testing::HasSubstr("Invalid value of SVG attribute"));
}

TEST(SvgImportArcsTest, ZeroRadiusArcIsAStraightLine) {
  absl::StatusOr<Drawing> line = ImportSvg(Svg("<path d=\"M 0 0 L 10 0 A 0 5 0 0 1 10 10 Z\"/>"));
  ASSERT_TRUE(line.ok()) << line.status();
  EXPECT_EQ(line->outlines[0].points.size(), 3u);  // the arc added just its end point
  absl::StatusOr<Drawing> both =
      ImportSvg(Svg("<path d=\"M 10 50 A 40 40 0 1 1 90 50 A 0 40 40 0 1 10 50 Z\"/>"));
  ASSERT_TRUE(both.ok()) << both.status();
  for (const Point& p : both->outlines[0].points) EXPECT_TRUE(p.allFinite());
}

TEST(SvgImportArcsTest, CirclePointsLieOnTheCircle) {
  SvgImportOptions options;
  options.tolerance = 0.01;
  absl::StatusOr<Drawing> d = ImportSvg(Svg("<circle cx=\"5\" cy=\"-3\" r=\"20\"/>"), options);
  ASSERT_TRUE(d.ok()) << d.status();
  const Points& p = d->outlines[0].points;
  EXPECT_GT(p.size(), 32u);
  for (const Point& q : p) EXPECT_NEAR((q - Point(5, -3)).norm(), 20.0, 0.02);
}

TEST(SvgImportArcsTest, TooSmallRadiiAreScaledUpToASemicircle) {
  // F.6.6: radii too small to reach the end point are scaled up (here to radius 10).
  absl::StatusOr<Drawing> d = ImportSvg(Svg("<path d=\"M 0 0 A 1 1 0 0 1 20 0 Z\"/>"));
  ASSERT_TRUE(d.ok()) << d.status();
  for (const Point& q : d->outlines[0].points) {
    EXPECT_NEAR((q - Point(10, 0)).norm(), 10.0, 0.1);
    EXPECT_LE(q.y(), 1e-9);  // sweep-flag 1 from (0,0) to (20,0) runs through y < 0
  }
}

TEST(SvgImportArcsTest, RotatedEllipseArcEndsOnItsEndPoint) {
  absl::StatusOr<Drawing> d = ImportSvg(Svg("<path d=\"M 0 0 A 30 10 30 1 0 15 20 L 0 20 Z\"/>"));
  ASSERT_TRUE(d.ok()) << d.status();
  bool found = false;
  for (const Point& q : d->outlines[0].points) found |= (q - Point(15, 20)).norm() < 1e-9;
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace inbetween::solver
