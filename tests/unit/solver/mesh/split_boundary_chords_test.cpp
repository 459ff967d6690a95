// Tests for chord splitting: no triangle left with only boundary vertices, area unchanged.
#include "solver/mesh/split_boundary_chords.h"

#include <gtest/gtest.h>

#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

TEST(SplitBoundaryChordsTest, FanOfAConvexPolygon) {
  // A hexagon fanned from vertex 0: three chords (0-2, 0-3, 0-4).
  Points x = {{2, 0}, {1, 2}, {-1, 2}, {-2, 0}, {-1, -2}, {1, -2}};
  for (Point& p : x) p.y() = -p.y();  // make the listed order positive
  std::vector<Triangle> tris = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}};
  for (Triangle& t : tris) std::swap(t[1], t[2]);
  for (Triangle& t : tris) ASSERT_GT(SignedArea2(t, x), 0);
  std::vector<bool> boundary(6, true);
  double area = 0;
  for (const Triangle& t : tris) area += SignedArea2(t, x);
  EXPECT_EQ(SplitBoundaryChords(&x, &tris, &boundary), 3);
  EXPECT_EQ(x.size(), 9u);
  EXPECT_EQ(tris.size(), 10u);
  double after = 0;
  for (const Triangle& t : tris) {
    EXPECT_GT(SignedArea2(t, x), 0);
    after += SignedArea2(t, x);
    EXPECT_FALSE(boundary[t[0]] && boundary[t[1]] && boundary[t[2]]);
  }
  EXPECT_NEAR(after, area, 1e-12);
}

}  // namespace
}  // namespace inbetween::solver
