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

}  // namespace
}  // namespace inbetween::solver
