// Tests for boundary correspondence: equal counts, recovered shifts, error statuses.
#include "solver/geometry/correspondence.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/geometry/polygon.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

Drawing Single(Points p) { return Drawing{{Outline{std::move(p)}}}; }

Points Blob(int n, double phase = 0.0) {
  Points p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n + phase;
    const double r = 50 + 15 * std::cos(3 * a) + 5 * std::sin(a);  // asymmetric, smooth
    p.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return p;
}

TEST(CorrespondenceTest, EqualCountsPositiveSimpleBoundaries) {
  const Points square = {{0, 0}, {100, 0}, {100, 100}, {0, 100}};
  Points hexagon;
  for (int i = 0; i < 6; ++i)
    hexagon.emplace_back(60 + 55 * std::cos(i * M_PI / 3), 60 + 55 * std::sin(i * M_PI / 3));
  Points reversed_blob = Blob(200);
  std::reverse(reversed_blob.begin(), reversed_blob.end());  // negative: gets reoriented
  absl::StatusOr<Correspondence> c =
      ComputeCorrespondence({Single(square), Single(hexagon), Single(reversed_blob)}, {});
  ASSERT_TRUE(c.ok()) << c.status();
  ASSERT_EQ(c->boundaries.size(), 3u);
  for (const Points& b : c->boundaries) {
    EXPECT_EQ(b.size(), c->boundaries[0].size());
    EXPECT_GE(b.size(), 64u);
    EXPECT_GT(PolygonSignedArea(b), 0);
    EXPECT_FALSE(FindSelfIntersection(b).has_value());
  }
}

TEST(CorrespondenceTest, RotatedIndexCopyFindsTheShiftBack) {
  const Points blob = Blob(96);
  for (int rotation : {1, 17, 50, 95}) {
    Points rotated = blob;
    std::rotate(rotated.begin(), rotated.begin() + rotation, rotated.end());
    // Translated and scaled copy: the match is on normalised positions.
    for (Point& p : rotated) p = 2.0 * p + Point(300, -40);
    CorrespondenceOptions options;
    options.vertices = 96;
    absl::StatusOr<Correspondence> c =
        ComputeCorrespondence({Single(blob), Single(rotated)}, options);
    ASSERT_TRUE(c.ok()) << c.status();
    // Arc-length samples start at each outline's own first vertex, so the copy's samples sit up
    // to one spacing away from the reference's; a wrong shift would be many spacings off.
    const int off = std::abs(c->shifts[1] - (96 - rotation) % 96);
    EXPECT_LE(std::min(off, 96 - off), 1) << "rotation " << rotation;
    double perimeter = 0;
    for (int k = 0; k < 96; ++k) perimeter += (blob[(k + 1) % 96] - blob[k]).norm();
    for (int k = 0; k < 96; ++k) {
      EXPECT_LT((c->boundaries[1][k] - (2.0 * c->boundaries[0][k] + Point(300, -40))).norm(),
                2.0 * perimeter / 96)
          << "rotation " << rotation << " k " << k;
    }
  }
}

TEST(CorrespondenceTest, SeveralOutlinesAreUnimplementedNamingTheDrawing) {
  Drawing two;
  two.outlines.push_back({{{0, 0}, {10, 0}, {10, 10}, {0, 10}}});
  two.outlines.push_back({{{2, 2}, {2, 8}, {8, 8}, {8, 2}}});  // hole (negative)
  absl::StatusOr<Correspondence> c = ComputeCorrespondence({Single(Blob(20)), two}, {});
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), absl::StatusCode::kUnimplemented);
  EXPECT_THAT(c.status().message(), HasSubstr("drawing 1 has 2 outlines (1 components, 1 holes)"));
}

TEST(CorrespondenceTest, DegenerateDrawingsAreInvalidWithLocation) {
  struct Case {
    Points points;
    const char* expected;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Case cases[] = {
      {{{0, 0}, {10, 10}, {10, 0}, {0, 10}}, "drawing 1: outline crosses itself at (5, 5)"},
      {{{0, 0}, {5, 0}, {0, 0}, {5, 0}}, "drawing 1: outline has only 2 distinct point(s)"},
      {{{0, 0}, {5, 5}, {10, 10}}, "drawing 1: outline crosses itself at (10, 10)"},
      {{{0, 0}, {10, 0}, {5, 1e-12}}, "drawing 1: outline encloses no area"},
      {{{0, 0}, {nan, 0}, {0, 10}}, "drawing 1: point 1 is not finite"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<Correspondence> r =
        ComputeCorrespondence({Single(Blob(30)), Single(c.points)}, {});
    ASSERT_FALSE(r.ok()) << c.expected;
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(r.status().message(), HasSubstr(c.expected));
  }
}

}  // namespace
}  // namespace inbetween::solver
