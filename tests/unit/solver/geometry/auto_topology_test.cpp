// Tests solver/geometry/auto_topology.cpp: the proposed cuts bring every drawing into one
// equivalence class (checked again with BuildBoundaries here), are straight segments inside the
// shape joining a hole to its outline, are the shortest such, and refused cases say what to do.
#include "solver/geometry/auto_topology.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/geometry/polygon.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

// Axis-aligned rectangle, positive in y-down coordinates when `hole` is false.
Outline Rect(double x0, double y0, double x1, double y1, bool hole = false) {
  Outline o{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}};
  if (hole == (PolygonSignedArea(o.points) > 0)) std::reverse(o.points.begin(), o.points.end());
  return o;
}

Outline Circle(double cx, double cy, double r, int n, bool hole = false) {
  Outline o;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    o.points.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
  }
  if (hole == (PolygonSignedArea(o.points) > 0)) std::reverse(o.points.begin(), o.points.end());
  return o;
}

EquivalenceClass ClassOf(Drawing d, const std::vector<Points>& cuts, int number) {
  for (const Points& c : cuts) d.cuts.push_back(c);
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, number);
  EXPECT_TRUE(g.ok()) << g.status();
  return g.ok() ? g->equivalence : EquivalenceClass{};
}

void ExpectOneClass(const std::vector<Drawing>& drawings, const AutoTopologyResult& r) {
  ASSERT_EQ(r.cuts.size(), drawings.size());
  for (size_t d = 0; d < drawings.size(); ++d) {
    EXPECT_EQ(ClassOf(drawings[d], r.cuts[d], static_cast<int>(d) + 1), r.target)
        << "drawing " << d + 1;
  }
}

TEST(AutoTopologyTest, RingVersusDiscCutsTheRingAtItsThinnestPlace) {
  // The hole sits off-centre: the band is 2 wide on the right, 8 on the left.
  const Drawing disc{{Circle(50, 50, 30, 64)}};
  const Drawing ring{{Rect(0, 0, 40, 40), Rect(8, 10, 38, 30, /*hole=*/true)}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({disc, ring});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->target.components, 1);
  EXPECT_EQ(r->target.holes, 0);
  EXPECT_TRUE(r->cuts[0].empty());
  ASSERT_EQ(r->cuts[1].size(), 1u);
  const Points& cut = r->cuts[1][0];
  ASSERT_EQ(cut.size(), 2u);
  // Across the right side band (2 wide), overhanging both ends by 1% as docs/svg-convention.md
  // asks of a cut (the builder clips the overhang).
  EXPECT_NEAR(cut[0].x(), 38.0 - 0.02, 1e-9);  // starts in the hole
  EXPECT_NEAR(cut[1].x(), 40.0 + 0.02, 1e-9);  // ends outside the outline
  EXPECT_NEAR(cut[0].y(), cut[1].y(), 1e-12);
  EXPECT_GE(cut[0].y(), 10.0);
  EXPECT_LE(cut[0].y(), 30.0);
  ASSERT_EQ(r->notes.size(), 1u);
  EXPECT_THAT(r->notes[0], HasSubstr("drawing 2: cut from the hole"));
  ExpectOneClass({disc, ring}, *r);
}

TEST(AutoTopologyTest, TwoHolesVersusOneCutsOnlyTheSmallerHole) {
  const Drawing one{{Rect(0, 0, 100, 60), Rect(20, 20, 40, 40, true)}};
  const Drawing two{{Rect(0, 0, 100, 60), Rect(20, 20, 40, 40, true), Rect(70, 25, 80, 35, true)}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({one, two});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->target.holes, 1);
  EXPECT_TRUE(r->cuts[0].empty());
  ASSERT_EQ(r->cuts[1].size(), 1u);
  const Points& cut = r->cuts[1][0];
  // From the small hole (x in [70, 80]) to the nearest outline side: 20 to the right edge.
  EXPECT_GE(cut[0].x(), 70);
  EXPECT_GT(cut[1].x(), 100);
  EXPECT_NEAR((cut[1] - cut[0]).norm(), 20.0 * 1.02, 1e-9);
  ExpectOneClass({one, two}, *r);
}

TEST(AutoTopologyTest, BothDrawingsLoseHolesDownToTheCommonCount) {
  const Drawing a{{Rect(0, 0, 100, 100), Rect(10, 10, 20, 20, true), Rect(60, 60, 70, 70, true)}};
  const Drawing b{{Rect(0, 0, 100, 100), Rect(40, 40, 50, 50, true)}};
  const Drawing c{{Circle(50, 50, 40, 48), Circle(50, 50, 10, 24, true),
                   Circle(30, 50, 4, 16, true), Circle(70, 50, 4, 16, true)}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({a, b, c});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->target.holes, 1);
  EXPECT_EQ(r->cuts[0].size(), 1u);
  EXPECT_EQ(r->cuts[1].size(), 0u);
  EXPECT_EQ(r->cuts[2].size(), 2u);
  ExpectOneClass({a, b, c}, *r);
}

TEST(AutoTopologyTest, CutGoesAroundAHoleInTheWay) {
  // The small extra hole is 42 below the top edge, but a wide hole lies in between; the next
  // shortest cuts go 45 to the left or right edge.
  const Drawing plain{{Rect(0, 0, 100, 100), Rect(10, 5, 90, 40, true)}};
  const Drawing extra{
      {Rect(0, 0, 100, 100), Rect(10, 5, 90, 40, true), Rect(45, 42, 55, 50, true)}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({plain, extra});
  ASSERT_TRUE(r.ok()) << r.status();
  ASSERT_EQ(r->cuts[1].size(), 1u);
  const Points& cut = r->cuts[1][0];
  EXPECT_NEAR((cut[1] - cut[0]).norm(), 45.0 * 1.02, 1e-9);
  EXPECT_GT(cut[1].y(), 40.0);
  for (double t : {0.25, 0.5, 0.75}) {
    const Point p = cut[0] + t * (cut[1] - cut[0]);
    EXPECT_FALSE(p.y() > 5 && p.y() < 40 && p.x() > 10 && p.x() < 90) << "crosses the big hole";
  }
  ExpectOneClass({plain, extra}, *r);
}

TEST(AutoTopologyTest, SameClassProposesNothing) {
  const Drawing a{{Rect(0, 0, 10, 10), Rect(3, 3, 6, 6, true)}};
  const Drawing b{{Circle(5, 5, 5, 32), Circle(5, 5, 2, 16, true)}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({a, b});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->cuts[0].empty() && r->cuts[1].empty());
  EXPECT_TRUE(r->notes.empty());
  EXPECT_EQ(r->target.holes, 1);
}

TEST(AutoTopologyTest, ExistingCutsCountAlready) {
  Drawing ring{{Rect(0, 0, 40, 40), Rect(10, 10, 30, 30, true)}};
  ring.cuts.push_back({{20, 30}, {20, 40}});  // already joins the hole to the outline
  const Drawing disc{{Rect(0, 0, 40, 40)}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({ring, disc});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->cuts[0].empty());
}

TEST(AutoTopologyTest, OnePieceIsSplitAtItsNeckToMatchTwo) {
  // A dumbbell: two 20x20 squares joined by a bar 4 high and 10 long; the other drawing has the
  // two squares apart. The cut goes across the bar (4 long), not across a square.
  const Drawing dumbbell{{Outline{{{0, 0},
                                   {20, 0},
                                   {20, 8},
                                   {30, 8},
                                   {30, 0},
                                   {50, 0},
                                   {50, 20},
                                   {30, 20},
                                   {30, 12},
                                   {20, 12},
                                   {20, 20},
                                   {0, 20}}}}};
  const Drawing apart{{Rect(0, 0, 20, 20), Rect(30, 0, 50, 20)}};
  ASSERT_GT(PolygonSignedArea(dumbbell.outlines[0].points), 0);
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({apart, dumbbell});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->target.components, 2);
  EXPECT_TRUE(r->cuts[0].empty());
  ASSERT_EQ(r->cuts[1].size(), 1u);
  const Points& cut = r->cuts[1][0];
  EXPECT_NEAR(cut[0].x(), cut[1].x(), 1e-9);  // vertical, across the bar
  EXPECT_GE(cut[0].x(), 20.0);
  EXPECT_LE(cut[0].x(), 30.0);
  EXPECT_NEAR(std::abs(cut[1].y() - cut[0].y()), 4.0 * 1.02, 1e-9);
  EXPECT_THAT(r->notes[0], HasSubstr("drawing 2: cut across the piece"));
  ExpectOneClass({apart, dumbbell}, *r);
}

TEST(AutoTopologyTest, SplitThenHoles) {
  // Drawing 1: one ring-shaped piece with a neck; drawing 2: two plain squares. After the split
  // drawing 1 has a hole in one piece that drawing 2 lacks, which the hole step then cuts.
  Drawing ringbell{{Outline{{{0, 0},
                             {20, 0},
                             {20, 8},
                             {30, 8},
                             {30, 0},
                             {50, 0},
                             {50, 20},
                             {30, 20},
                             {30, 12},
                             {20, 12},
                             {20, 20},
                             {0, 20}}},
                    Rect(5, 5, 15, 15, true)}};
  const Drawing apart{{Rect(0, 0, 20, 20), Rect(30, 0, 50, 20)}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({ringbell, apart});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->target.components, 2);
  EXPECT_EQ(r->target.holes, 0);
  EXPECT_EQ(r->cuts[0].size(), 2u);
  ExpectOneClass({ringbell, apart}, *r);
}

TEST(AutoTopologyTest, NoNeckToSplitIsRefusedWithAdvice) {
  // A thin ring has no chord inside it that splits it (every chord crosses the hole).
  const Drawing ring{{Circle(50, 50, 40, 64), Circle(50, 50, 38, 64, true)}};
  const Drawing two{{Rect(0, 0, 10, 10, false), Rect(20, 0, 30, 10, false), Rect(2, 2, 4, 4, true),
                     Rect(22, 2, 24, 4, true)}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({ring, two});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(r.status().message(), HasSubstr("drawing 1 has 1 component, 1 hole"));
  EXPECT_THAT(r.status().message(), HasSubstr("\"cuts\""));
}

TEST(AutoTopologyTest, BadDrawingNamesIt) {
  const Drawing ok{{Rect(0, 0, 10, 10)}};
  const Drawing bowtie{{Outline{{{0, 0}, {10, 10}, {10, 0}, {0, 10}}}}};
  absl::StatusOr<AutoTopologyResult> r = ProposeTopology({ok, bowtie});
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("drawing 2"));
}

}  // namespace
}  // namespace inbetween::solver
