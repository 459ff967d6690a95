// Tests for arc-length resampling: exact count, corners kept, points on the outline.
#include "solver/geometry/resample_outline.h"

#include <gtest/gtest.h>

#include <cmath>

#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

double DistanceToOutline(const Points& outline, const Point& p) {
  double best = INFINITY;
  for (size_t i = 0; i < outline.size(); ++i) {
    best = std::min(best, DistanceToSegment(p, outline[i], outline[(i + 1) % outline.size()]));
  }
  return best;
}

TEST(ResampleOutlineTest, KeepsCornersAndCount) {
  const Points rect = {{0, 0}, {30, 0}, {30, 10}, {0, 10}};
  for (int count : {4, 7, 8, 33, 64}) {
    const Points r = ResampleOutline(rect, count);
    ASSERT_EQ(static_cast<int>(r.size()), count);
    for (const Point& corner : rect) {
      EXPECT_TRUE(std::any_of(r.begin(), r.end(), [&](const Point& p) { return p == corner; }))
          << count;
    }
    for (const Point& p : r) EXPECT_LT(DistanceToOutline(rect, p), 1e-9);
  }
}

TEST(ResampleOutlineTest, SmoothOutlineIsUniformByArcLength) {
  Points circle;
  for (int i = 0; i < 360; ++i)
    circle.emplace_back(std::cos(i * M_PI / 180), std::sin(i * M_PI / 180));
  const Points r = ResampleOutline(circle, 50);
  ASSERT_EQ(r.size(), 50u);
  EXPECT_EQ(r[0], circle[0]);
  for (size_t i = 0; i < r.size(); ++i) {
    EXPECT_NEAR((r[(i + 1) % r.size()] - r[i]).norm(), 2 * M_PI / 50, 1e-3);
  }
}

TEST(ResampleOutlineTest, TooManyCornersFallsBackToUniform) {
  const Points hexagon = {{2, 0}, {1, 1.7}, {-1, 1.7}, {-2, 0}, {-1, -1.7}, {1, -1.7}};
  EXPECT_EQ(ResampleOutline(hexagon, 4).size(), 4u);
}

}  // namespace
}  // namespace inbetween::solver
