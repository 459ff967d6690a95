// Robust geometry (docs/bad-input.md): crossing decisions use exact predicates, and the O(n^2)
// crossing sweeps are bounded so a comb of long overlapping teeth cannot pin a core for hours.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "solver/geometry/graph_flow.h"
#include "solver/geometry/polygon.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

// A simple polygon: a spine at x in [0, 1] with `teeth` teeth reaching x = 1000.
Points Comb(int teeth) {
  Points p = {{0, 2.0 * teeth}};
  for (int k = teeth - 1; k >= 0; --k) {
    p.emplace_back(1, 2.0 * k + 2);
    p.emplace_back(1, 2.0 * k + 1);
    p.emplace_back(1000, 2.0 * k + 1);
    p.emplace_back(1000, 2.0 * k);
  }
  p.emplace_back(0, 0);
  std::reverse(p.begin(), p.end());  // positive signed area (y down)
  return p;
}

TEST(RobustGeometryTest, CombIsSimpleAndPositive) {
  const Points comb = Comb(50);
  EXPECT_GT(PolygonSignedArea(comb), 0);
  bool gave_up = true;
  EXPECT_FALSE(FindSelfIntersection(comb, -1, &gave_up));
  EXPECT_FALSE(gave_up);
}

TEST(RobustGeometryTest, SelfIntersectionSearchStopsAtItsBudget) {
  const Points comb = Comb(2000);
  bool gave_up = false;
  EXPECT_FALSE(FindSelfIntersection(comb, 10000, &gave_up));
  EXPECT_TRUE(gave_up);
  EXPECT_FALSE(FindSelfIntersection(comb, 100'000'000, &gave_up));
  EXPECT_FALSE(gave_up);
}

TEST(RobustGeometryTest, GraphFlowRefusesTooManyOverlappingSegments) {
  Drawing d;
  d.outlines = {{Comb(2000)}};
  BoundaryOptions options;
  options.max_pair_checks = 10000;
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, 3, options);
  EXPECT_EQ(g.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(g.status().message(), HasSubstr("drawing 3: more than 10000 pairs"));
  EXPECT_TRUE(BuildBoundaries(d, 3).ok());  // the default bound leaves room for it
}

TEST(RobustGeometryTest, ThinSpikesAndFoldsAreDecidedExactly) {
  // A spike 1e-12 thick is still simple (its two sides never meet)...
  const Points spike = {{0, 0}, {10, 0}, {20, 1e-12}, {10, 5e-13}, {0, 1}};
  EXPECT_FALSE(FindSelfIntersection(spike));
  // ...but folding back along the same line is a contact.
  const Points fold = {{0, 0}, {10, 0}, {5, 0}, {5, 5}};
  EXPECT_TRUE(FindSelfIntersection(fold));
}

TEST(RobustGeometryTest, TouchingAtAVertexIsAContact) {
  // Vertex 3 lies exactly on segment 0 (a pinch): not a simple polygon.
  const Points pinch = {{0, 0}, {10, 0}, {10, 10}, {5, 0}, {0, 10}};
  std::optional<SelfIntersection> x = FindSelfIntersection(pinch);
  ASSERT_TRUE(x);
  EXPECT_EQ(x->location, Point(5, 0));
}

}  // namespace
}  // namespace inbetween::solver
