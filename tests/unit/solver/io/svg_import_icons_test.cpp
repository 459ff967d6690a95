// Regressions in solver/io/svg_import.cpp found on third-party icons (bootstrap-icons 1.13.2,
// tests/e2e/cli_icons_test.sh):
// - fill-rule nonzero with touching subpaths: a subpath beside another (sharing a vertex or
//   running along it) is not nested in it, so it is kept. "dropbox": its first subpath starts at
//   a vertex of its third one, the test at that first point said "inside", and the whole left
//   half of the logo was dropped as a same-direction inner subpath (exit 0, a wrong mesh).
// - a subpath of collinear points has no area also after a transform: "emoji-kiss" got one hole
//   more when rotated (area 1e-17 instead of 0), so the icon and its rotated copy differed in
//   topology.
#include <gtest/gtest.h>

#include <string>

#include "solver/geometry/polygon.h"
#include "solver/io/svg_import.h"

namespace inbetween::solver {
namespace {

Drawing ImportOk(const std::string& body) {
  absl::StatusOr<Drawing> d = ImportSvg("<svg xmlns=\"http://www.w3.org/2000/svg\">" + body + "</svg>");
  EXPECT_TRUE(d.ok()) << d.status();
  return d.ok() ? *d : Drawing{};
}

double TotalArea(const Drawing& d) {
  double area = 0;
  for (const Outline& o : d.outlines) area += PolygonSignedArea(o.points);
  return area;
}

TEST(SvgImportIconsTest, DropboxLogoKeepsEverySubpath) {
  // bootstrap-icons 1.13.2 icons/dropbox.svg, verbatim: three same-direction subpaths side by
  // side, the first and the third touching at (8.01, 4.555).
  Drawing d = ImportOk(
      "<path d=\"M8.01 4.555 4.005 7.11 8.01 9.665 4.005 12.22 0 9.651l4.005-2.555L0 4.555 "
      "4.005 2zm-4.026 8.487 4.006-2.555 4.005 2.555-4.005 2.555zm4.026-3.39 4.005-2.556L8.01 "
      "4.555 11.995 2 16 4.555 11.995 7.11 16 9.665l-4.005 2.555z\"/>");
  ASSERT_EQ(d.outlines.size(), 3u);
  for (const Outline& o : d.outlines) EXPECT_GT(PolygonSignedArea(o.points), 0);
  EXPECT_NEAR(TotalArea(d), 40.9311 + 20.468105 + 40.77793, 1e-6);
}

TEST(SvgImportIconsTest, SubpathStartingOnAnotherIsBesideIt) {
  // Two squares drawn the same way, the second starting at the first one's corner (10, 0) and
  // at the middle of its right side (10, 5): neither is inside the other.
  for (const char* second : {"M10 0 H20 V10 H10 Z", "M10 5 V0 H20 V10 H10 Z"}) {
    Drawing d = ImportOk(std::string("<path d=\"M0 0 H10 V10 H0 Z ") + second + "\"/>");
    EXPECT_EQ(d.outlines.size(), 2u) << second;
    EXPECT_NEAR(TotalArea(d), 200, 1e-9) << second;
  }
  // A square touching the inside of a ring at a vertex is still inside it: an island in the
  // ring's hole under nonzero (windings 1 | 0 | 1), as without the touch.
  Drawing island = ImportOk(
      "<path d=\"M0 0 H100 V100 H0 Z M20 20 V80 H80 V20 Z M20 20 H40 V40 H20 Z\"/>");
  EXPECT_EQ(island.outlines.size(), 3u);
  // Same-direction inner square whose first point is on the outer one: filled on both sides,
  // dropped as before.
  Drawing inner = ImportOk("<path d=\"M0 0 H100 V100 H0 Z M0 50 L50 20 L80 50 L50 80 Z\"/>");
  EXPECT_EQ(inner.outlines.size(), 1u);
}

TEST(SvgImportIconsTest, CollinearSubpathHasNoAreaUnderAnyTransform) {
  // emoji-kiss's "m.766-.087-.003-.001-.003-.001z" (absolute here) beside a square.
  const std::string body =
      "<path fill-rule=\"evenodd\" d=\"M0 0 H8 V8 H0 Z M9.528 10.061 l-.003-.001-.003-.001z\"/>";
  for (const char* transform : {"translate(0 0)", "rotate(20)", "matrix(1.2 0.35 -0.25 1.1 30 -4)"}) {
    Drawing d = ImportOk(std::string("<g transform=\"") + transform + "\">" + body + "</g>");
    EXPECT_EQ(d.outlines.size(), 1u) << transform;
  }
  // A thin but real sliver (width 1e-3 of its length) stays.
  Drawing sliver = ImportOk("<path d=\"M0 0 H8 V8 H0 Z M10 0 L20 0.01 L10 0.02 Z\"/>");
  EXPECT_EQ(sliver.outlines.size(), 2u);
}

}  // namespace
}  // namespace inbetween::solver
