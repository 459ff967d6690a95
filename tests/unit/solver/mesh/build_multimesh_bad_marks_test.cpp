// Correspondence marks far from any boundary are refused (tests/data/bad/
// correspondence_off_boundary.json) instead of silently pinning the nearest boundary point.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/mesh/build_multimesh.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

Points Circle(double r, int n) {
  Points p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    p.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return p;
}

TEST(BuildMultimeshBadMarksTest, MarkFarFromTheBoundaryIsInvalidNamingDrawingAndMark) {
  Drawing a, b;
  a.outlines = {{Circle(10, 64)}};
  b.outlines = {{Circle(10, 64)}};
  a.marks = {{1, {10, 0}}};
  b.marks = {{1, {500, 500}}};
  absl::Status s = BuildMultimesh({a, b}, {}).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("drawing 2: correspondence mark 1 at (500, 500)"));
}

TEST(BuildMultimeshBadMarksTest, MarkSlightlyOffTheBoundaryStillPins) {
  Drawing a, b;
  a.outlines = {{Circle(10, 64)}};
  b.outlines = {{Circle(10, 64)}};
  a.marks = {{1, {10.5, 0}}};
  b.marks = {{1, {0, 9.6}}};
  absl::StatusOr<Multimesh> m = BuildMultimesh({a, b}, {});
  EXPECT_TRUE(m.ok()) << m.status();
}

// A mark computed by a program lands a hair off the drawn corner (an SVG written with four
// decimals): it snaps onto the corner instead of splitting the boundary into a sliver interval
// beside the corner's own breakpoint, which every drawing would repeat (the mesher refused the
// sliver as a cusp of the other drawing).
TEST(BuildMultimeshBadMarksTest, MarkAHairOffACornerSnapsOntoIt) {
  const Points arrow = {{0, 40}, {220, 40}, {220, 0}, {320, 70}, {220, 140}, {220, 100}, {0, 100}};
  Points longer;
  for (const Point& p : arrow) longer.emplace_back(p.x() < 200 ? p.x() : p.x() + 60.0, p.y());
  Drawing a, b;
  a.outlines = {{arrow}};
  b.outlines = {{longer}};
  for (size_t k = 0; k < arrow.size(); ++k) {
    const int id = static_cast<int>(k) + 1;
    a.marks.push_back({id, arrow[k]});
    b.marks.push_back({id, longer[k]});
  }
  // The tip's mark 5e-5 units off the corner, along the side into it.
  a.marks[3].point += Point(-5e-5, -3.5e-5);
  absl::StatusOr<Multimesh> m = BuildMultimesh({a, b}, {});
  ASSERT_TRUE(m.ok()) << m.status();
  bool tip = false;
  for (int v : m->pinned) {
    tip = tip || ((m->shapes[0][v] - arrow[3]).norm() < 1e-9 &&
                  (m->shapes[1][v] - longer[3]).norm() < 1e-9);
  }
  EXPECT_TRUE(tip) << "the tip's mark is not on the corner";
}

}  // namespace
}  // namespace inbetween::solver
