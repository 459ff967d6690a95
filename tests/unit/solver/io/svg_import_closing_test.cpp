// A filled subpath whose data stops a hair short of its start (bootstrap-icons rounds path data
// to three decimals: cash-coin's "$" ends "h-.668z" 0.001 before its first point) closes with a
// segment folding back along its neighbour. The importer drops such a last point (within the
// flatten tolerance and 1e-3 of the subpath's size); a real short closing edge stays.
#include <gtest/gtest.h>

#include <string>

#include "solver/geometry/polygon.h"
#include "solver/io/svg_import.h"

namespace inbetween::solver {
namespace {

Drawing Import(const std::string& path_data) {
  const std::string svg =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 16 16\"><path d=\"" + path_data +
      "\"/></svg>";
  absl::StatusOr<Drawing> d = ImportSvg(svg, {});
  EXPECT_TRUE(d.ok()) << d.status();
  return d.ok() ? *d : Drawing{};
}

TEST(SvgImportClosingTest, ClosingGapBelowTheToleranceIsDropped) {
  // A square from (9.438, 2) back to its start, then 0.001 further left: "z" would fold back.
  const Drawing d = Import("M9.438 2 h4 v4 h-4 v-4 h-.001 z");
  ASSERT_EQ(d.outlines.size(), 1u);
  const Points& p = d.outlines[0].points;
  ASSERT_EQ(p.size(), 4u) << "the point 0.001 past the start and the start repeated are dropped";
  EXPECT_EQ(p.front(), Point(9.438, 2));
  EXPECT_NE(PolygonSignedArea(p), 0.0);
}

TEST(SvgImportClosingTest, RealShortClosingEdgeStays) {
  // A 0.5 closing edge on a 4-unit square is geometry (above the 0.05 tolerance): kept.
  const Drawing d = Import("M2 2 h4 v4 h-3.5 z");
  ASSERT_EQ(d.outlines.size(), 1u);
  EXPECT_EQ(d.outlines[0].points.size(), 4u);
}

}  // namespace
}  // namespace inbetween::solver
