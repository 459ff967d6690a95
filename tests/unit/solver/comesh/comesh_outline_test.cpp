// Tests for the reference outlines comesh boundary vertices slide along (comesh_outline.h).
#include "solver/comesh/comesh_outline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace inbetween::solver {
namespace {

// A multimesh with only what ShapeOutline reads: one shape and its boundary loops.
Multimesh Loops(const std::vector<Points>& loops) {
  Multimesh m;
  m.shapes.emplace_back();
  for (const Points& loop : loops) {
    std::vector<int> ids;
    for (const Point& p : loop) {
      ids.push_back(static_cast<int>(m.shapes[0].size()));
      m.shapes[0].push_back(p);
    }
    m.boundary.insert(m.boundary.end(), ids.begin(), ids.end());
    m.boundary_loops.push_back(ids);
  }
  return m;
}

// The square [0, 2]^2 with its side midpoints, counter-clockwise from the origin: corners at arc
// lengths 0, 2, 4, 6 (turn 90 degrees), midpoints at 1, 3, 5, 7 (turn 0).
Points SquareWithMidpoints() {
  return {Point(0, 0), Point(1, 0), Point(2, 0), Point(2, 1),
          Point(2, 2), Point(1, 2), Point(0, 2), Point(0, 1)};
}

void ExpectNear(const Point& a, const Point& b) {
  EXPECT_NEAR(a.x(), b.x(), 1e-12) << a.transpose() << " vs " << b.transpose();
  EXPECT_NEAR(a.y(), b.y(), 1e-12) << a.transpose() << " vs " << b.transpose();
}

TEST(ShapeOutlineTest, LocatesPointsOnTheOutlineOnly) {
  const ShapeOutline outline(Loops({SquareWithMidpoints()}), 0, 25.0, {});
  ASSERT_EQ(outline.num_loops(), 1);
  EXPECT_DOUBLE_EQ(outline.length(0), 8.0);
  auto at = outline.Locate(Point(1.5, 0.0), 1e-9);
  ASSERT_TRUE(at.has_value());
  EXPECT_EQ(at->loop, 0);
  EXPECT_NEAR(at->u, 1.5, 1e-12);
  at = outline.Locate(Point(0.0, 0.25), 1e-9);  // on the last segment, (0, 1) -> (0, 0)
  ASSERT_TRUE(at.has_value());
  EXPECT_NEAR(at->u, 7.75, 1e-12);
  at = outline.Locate(Point(0.0, 0.0), 1e-9);  // the loop's start: wrapped into [0, 8)
  ASSERT_TRUE(at.has_value());
  EXPECT_TRUE(at->u < 1e-12 || at->u > 8.0 - 1e-12) << at->u;
  EXPECT_FALSE(outline.Locate(Point(1.5, 1e-6), 1e-9).has_value());
  EXPECT_FALSE(outline.Locate(Point(1.0, 1.0), 1e-9).has_value());
  EXPECT_FALSE(outline.Locate(Point(5.0, 0.0), 1e-9).has_value());
}

TEST(ShapeOutlineTest, PointsAndTangentsWrapAroundTheLoop) {
  const ShapeOutline outline(Loops({SquareWithMidpoints()}), 0, 25.0, {});
  ExpectNear(outline.At(0, 1.5), Point(1.5, 0.0));
  ExpectNear(outline.At(0, 1.5 + 8.0), Point(1.5, 0.0));
  ExpectNear(outline.At(0, 1.5 - 16.0), Point(1.5, 0.0));
  ExpectNear(outline.At(0, -0.5), Point(0.0, 0.5));
  ExpectNear(outline.At(0, 3.25), Point(2.0, 1.25));
  ExpectNear(outline.Tangent(0, 1.5), Point(1.0, 0.0));
  ExpectNear(outline.Tangent(0, 1.0), Point(1.0, 0.0));  // a straight polyline point
  ExpectNear(outline.Tangent(0, 4.5), Point(-1.0, 0.0));
  const double r = 1.0 / std::sqrt(2.0);
  ExpectNear(outline.Tangent(0, 2.0), Point(r, r));     // a corner: the bisector
  ExpectNear(outline.Tangent(0, 8.0), Point(r, -r));    // the start, reached from the end
  ExpectNear(outline.Tangent(0, -0.25), Point(0, -1));  // the last segment
}

TEST(ShapeOutlineTest, HardPointsAreSharpTurnsAndFixedVertices) {
  const ShapeOutline outline(Loops({SquareWithMidpoints()}), 0, 25.0, {});
  for (double u : {0.0, 2.0, 4.0, 6.0, 8.0 - 1e-13}) {
    EXPECT_TRUE(outline.AtHardPoint(0, u, 1e-9)) << u;
  }
  for (double u : {1.0, 3.0, 1.5, 7.0}) EXPECT_FALSE(outline.AtHardPoint(0, u, 1e-9)) << u;
  EXPECT_EQ(outline.Stretch(0, 1.5), std::make_pair(0.0, 2.0));
  EXPECT_EQ(outline.Stretch(0, 1.0), std::make_pair(0.0, 2.0));
  EXPECT_EQ(outline.Stretch(0, 9.5), std::make_pair(8.0, 10.0));   // unwrapped frame kept
  EXPECT_EQ(outline.Stretch(0, -0.5), std::make_pair(-2.0, 0.0));  // across the start
  EXPECT_EQ(outline.Stretch(0, 7.5), std::make_pair(6.0, 8.0));
  // A fixed vertex (a mark at the bottom midpoint, vertex 1) stops sliders too.
  const ShapeOutline marked(Loops({SquareWithMidpoints()}), 0, 25.0, {0, 1});
  EXPECT_TRUE(marked.AtHardPoint(0, 1.0, 1e-9));
  EXPECT_EQ(marked.Stretch(0, 1.5), std::make_pair(1.0, 2.0));
  EXPECT_EQ(marked.Stretch(0, 0.5), std::make_pair(0.0, 1.0));
  // With a threshold above 90 degrees the square has no hard point: one endless stretch.
  const ShapeOutline soft(Loops({SquareWithMidpoints()}), 0, 91.0, {});
  EXPECT_FALSE(soft.AtHardPoint(0, 2.0, 1e-9));
  const auto [lo, hi] = soft.Stretch(0, 1.5);
  EXPECT_EQ(lo, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(hi, std::numeric_limits<double>::infinity());
}

TEST(ShapeOutlineTest, ThresholdSeparatesACurveFromItsCorners) {
  Points dodecagon;  // turn 30 degrees at every point
  for (int k = 0; k < 12; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 12.0;
    dodecagon.push_back(Point(std::cos(a), std::sin(a)));
  }
  const Multimesh m = Loops({dodecagon});
  const ShapeOutline sharp(m, 0, 25.0, {}), smooth(m, 0, 35.0, {});
  const double side = (dodecagon[1] - dodecagon[0]).norm();
  for (int k = 0; k < 12; ++k) {
    EXPECT_TRUE(sharp.AtHardPoint(0, k * side, 1e-9)) << k;
    EXPECT_FALSE(smooth.AtHardPoint(0, k * side, 1e-9)) << k;
  }
}

TEST(ShapeOutlineTest, SplitPointsStayOnTheOutline) {
  // Soft corners at the midpoints (turn 0 there, 90 at the square's corners with 91 degrees).
  const ShapeOutline square(Loops({SquareWithMidpoints()}), 0, 25.0, {});
  // A straight stretch: the chord's midpoint, exactly.
  EXPECT_EQ(square.SplitPoint(Point(0.5, 0), Point(1.5, 0), 1e-9), Point(1.0, 0.0));
  // Across the corner (2, 0), a hard point: no split.
  EXPECT_FALSE(square.SplitPoint(Point(1.5, 0), Point(2, 0.5), 1e-9).has_value());
  // With the corners soft, the middle of the arc: the corner itself.
  const ShapeOutline soft(Loops({SquareWithMidpoints()}), 0, 91.0, {});
  auto p = soft.SplitPoint(Point(1.5, 0), Point(2, 0.5), 1e-9);
  ASSERT_TRUE(p.has_value());
  ExpectNear(*p, Point(2.0, 0.0));
  p = soft.SplitPoint(Point(2, 0.5), Point(1.5, 0), 1e-9);  // the other way round: the same arc
  ASSERT_TRUE(p.has_value());
  ExpectNear(*p, Point(2.0, 0.0));
  p = soft.SplitPoint(Point(0, 0.25), Point(0.75, 0), 1e-9);  // across the loop's start
  ASSERT_TRUE(p.has_value());
  ExpectNear(*p, Point(0.25, 0.0));
  // An end off the outline: no split.
  EXPECT_FALSE(soft.SplitPoint(Point(1.5, 0.1), Point(2, 0.5), 1e-9).has_value());
}

TEST(ShapeOutlineTest, LocatesTheRightLoopOfSeveral) {
  Points hole = {Point(0.5, 0.5), Point(0.5, 1.5), Point(1.5, 1.5), Point(1.5, 0.5)};  // clockwise
  const ShapeOutline outline(Loops({SquareWithMidpoints(), hole}), 0, 25.0, {});
  ASSERT_EQ(outline.num_loops(), 2);
  auto at = outline.Locate(Point(0.5, 1.0), 1e-9);
  ASSERT_TRUE(at.has_value());
  EXPECT_EQ(at->loop, 1);
  EXPECT_NEAR(at->u, 0.5, 1e-12);
  ExpectNear(outline.At(1, at->u), Point(0.5, 1.0));
  at = outline.Locate(Point(2.0, 1.5), 1e-9);
  ASSERT_TRUE(at.has_value());
  EXPECT_EQ(at->loop, 0);
}

}  // namespace
}  // namespace inbetween::solver
