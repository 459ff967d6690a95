// Tests for the polygon predicates: area sign, containment, convexity, self-intersection.
#include "solver/geometry/polygon.h"

#include <gtest/gtest.h>

namespace inbetween::solver {
namespace {

const Points kSquare = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};

TEST(PolygonTest, SignedAreaFollowsTheConvention) {
  EXPECT_DOUBLE_EQ(PolygonSignedArea(kSquare), 100.0);
  Points reversed(kSquare.rbegin(), kSquare.rend());
  EXPECT_DOUBLE_EQ(PolygonSignedArea(reversed), -100.0);
}

TEST(PolygonTest, Contains) {
  EXPECT_TRUE(PolygonContains(kSquare, {5, 5}));
  EXPECT_FALSE(PolygonContains(kSquare, {15, 5}));
  const Points l = {{0, 0}, {10, 0}, {10, 3}, {3, 3}, {3, 10}, {0, 10}};
  EXPECT_TRUE(PolygonContains(l, {1, 8}));
  EXPECT_FALSE(PolygonContains(l, {8, 8}));
}

TEST(PolygonTest, Convexity) {
  EXPECT_TRUE(IsConvexPositive(kSquare));
  EXPECT_TRUE(IsConvexPositive({{0, 0}, {5, 0}, {10, 0}, {10, 10}, {0, 10}}));  // collinear ok
  EXPECT_FALSE(IsConvexPositive(Points(kSquare.rbegin(), kSquare.rend())));
  EXPECT_FALSE(IsConvexPositive({{0, 0}, {10, 0}, {10, 3}, {3, 3}, {3, 10}, {0, 10}}));
}

TEST(PolygonTest, SimplePolygonsHaveNoSelfIntersection) {
  EXPECT_FALSE(FindSelfIntersection(kSquare).has_value());
  EXPECT_FALSE(FindSelfIntersection({{0, 0}, {10, 0}, {10, 3}, {3, 3}, {3, 10}, {0, 10}}));
  EXPECT_FALSE(FindSelfIntersection({{0, 0}, {1, 0}, {0, 1}}));
}

TEST(PolygonTest, BowTieCrossingIsLocated) {
  auto hit = FindSelfIntersection({{0, 0}, {10, 10}, {10, 0}, {0, 10}});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->location.x(), 5.0, 1e-12);
  EXPECT_NEAR(hit->location.y(), 5.0, 1e-12);
}

TEST(PolygonTest, TouchingAndFoldingBackAreIntersections) {
  // A vertex touching another edge.
  EXPECT_TRUE(FindSelfIntersection({{0, 0}, {10, 0}, {10, 10}, {5, 0.0}, {0, 10}}).has_value());
  // A spike folding back along the previous edge.
  EXPECT_TRUE(FindSelfIntersection({{0, 0}, {10, 0}, {5, 0}, {5, 10}}).has_value());
}

}  // namespace
}  // namespace inbetween::solver
