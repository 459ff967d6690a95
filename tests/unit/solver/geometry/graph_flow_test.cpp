// S-Alg.1 property tests: visit counts, boundary counts and orientation on hand-made graphs and
// drawings with cuts and openings; error cases with their locations.
#include "solver/geometry/graph_flow.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "solver/geometry/polygon.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

Points Square(double size = 10) { return {{0, 0}, {size, 0}, {size, size}, {0, size}}; }

TEST(DirectedGraphFlowTest, SquareWithDanglingCutVisitsCounts) {
  // Square 0-1-2-3 (positive), a cut from the bottom midpoint 4 to the centre 5.
  const Points nodes = {{0, 0}, {5, 0}, {10, 0}, {10, 10}, {0, 10}, {5, 5}};
  const std::vector<GraphEdge> edges = {{0, 1, false}, {1, 2, false}, {2, 3, false},
                                        {3, 4, false}, {4, 0, false}, {1, 5, true}};
  absl::StatusOr<GraphFlowResult> flow = DirectedGraphFlow(nodes, edges);
  ASSERT_TRUE(flow.ok()) << flow.status();
  EXPECT_EQ(flow->visits, (std::vector<int>{1, 1, 1, 1, 1, 2}));
  ASSERT_EQ(flow->cycles.size(), 1u);
  // The walk goes up the cut right after arriving at its foot.
  EXPECT_EQ(flow->cycles[0].nodes, (std::vector<int>{0, 1, 5, 1, 2, 3, 4}));
}

TEST(DirectedGraphFlowTest, FullCutGivesTwoCycles) {
  const Points nodes = {{0, 0}, {10, 0}, {10, 5}, {10, 10}, {0, 10}, {0, 5}};
  const std::vector<GraphEdge> edges = {{0, 1, false}, {1, 2, false}, {2, 3, false}, {3, 4, false},
                                        {4, 5, false}, {5, 0, false}, {5, 2, true}};
  absl::StatusOr<GraphFlowResult> flow = DirectedGraphFlow(nodes, edges);
  ASSERT_TRUE(flow.ok()) << flow.status();
  EXPECT_EQ(flow->cycles.size(), 2u);
  EXPECT_EQ(flow->visits.back(), 2);
  for (const FlowCycle& c : flow->cycles) {
    Points p;
    for (int n : c.nodes) p.push_back(nodes[n]);
    EXPECT_NEAR(PolygonSignedArea(p), 50.0, 1e-12);
  }
}

TEST(DirectedGraphFlowTest, DanglingOutlineCannotClose) {
  const Points nodes = {{0, 0}, {10, 0}, {10, 10}};
  absl::Status s = DirectedGraphFlow(nodes, {{0, 1, false}, {1, 2, false}}).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("cannot close: it stops at (10, 10)"));
}

TEST(BuildBoundariesTest, PlainOutlinesAndHoles) {
  Drawing d;
  d.outlines.push_back({Square(10)});
  Points hole = {{3, 3}, {3, 6}, {6, 6}, {6, 3}};
  d.outlines.push_back({hole});
  d.outlines.push_back({{{20, 0}, {30, 0}, {30, 10}}});
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, 1);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_EQ(g->equivalence.components, 2);
  EXPECT_EQ(g->equivalence.holes, 1);
  EXPECT_EQ(g->equivalence.ToString(), "2 components, 1 hole (per component 1+0)");
  ASSERT_EQ(g->loops.size(), 3u);
  EXPECT_TRUE(g->loops[0].outer && g->loops[1].outer && !g->loops[2].outer);
  EXPECT_GT(PolygonSignedArea(g->loops[0].points), 0);
  EXPECT_LT(PolygonSignedArea(g->loops[2].points), 0);
  EXPECT_EQ(g->loops[2].component, g->loops[0].component);
  EXPECT_EQ(g->bi_directed_edges, 0);
}

TEST(BuildBoundariesTest, OpeningInsideMakesAnnulus) {
  Drawing d;
  d.outlines.push_back({Square(10)});
  d.openings.push_back({{3, 5}, {5, 5.5}, {7, 5}});
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, 1);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_EQ(g->equivalence.ToString(), "1 component, 1 hole");
  ASSERT_EQ(g->loops.size(), 2u);
  const BoundaryLoop& slit = g->loops[1];
  EXPECT_FALSE(slit.outer);
  EXPECT_EQ(slit.points.size(), 4u);  // 2 segments walked both ways
  EXPECT_EQ(PolygonSignedArea(slit.points), 0.0);
  for (size_t k = 0; k < slit.twin.size(); ++k) {
    const auto [l, e] = slit.twin[k];
    ASSERT_EQ(l, 1);
    EXPECT_EQ(slit.twin[e].second, static_cast<int>(k));  // involution
    EXPECT_EQ(slit.points[e], slit.points[(k + 1) % 4]);  // walked the other way
  }
}

TEST(BuildBoundariesTest, FullCutSplitsIntoTwoComponents) {
  Drawing d;
  d.outlines.push_back({Square(10)});
  d.cuts.push_back({{-1, 4}, {5, 5}, {11, 6}});  // overshoots on both sides: clipped
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, 2);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_EQ(g->equivalence.ToString(), "2 components, 0 holes");
  EXPECT_EQ(g->bi_directed_edges, 2);
  EXPECT_EQ(g->one_directed_edges, 6);  // two outline segments split by the cut
  double total = 0;
  int twins = 0;
  for (const BoundaryLoop& loop : g->loops) {
    EXPECT_TRUE(loop.outer);
    total += PolygonSignedArea(loop.points);
    for (const auto& t : loop.twin) twins += t.first >= 0;
  }
  EXPECT_NEAR(total, 100.0, 1e-9);
  EXPECT_EQ(twins, 4);
}

TEST(BuildBoundariesTest, CutFromBoundaryIsASlitWithoutTopologyChange) {
  Drawing d;
  d.outlines.push_back({Square(10)});
  d.cuts.push_back({{5, -2}, {5, 5}});
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, 1);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_EQ(g->equivalence.ToString(), "1 component, 0 holes");
  EXPECT_EQ(g->loops[0].points.size(), 7u);
}

TEST(BuildBoundariesTest, HoleOrientationFollowsNestingWhateverTheInput) {
  Drawing d;
  Points outer = Square(10);
  std::reverse(outer.begin(), outer.end());
  d.outlines.push_back({outer});
  d.outlines.push_back({{{3, 3}, {6, 3}, {6, 6}, {3, 6}}});  // positive as given
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, 1);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_GT(PolygonSignedArea(g->loops[0].points), 0);
  EXPECT_LT(PolygonSignedArea(g->loops[1].points), 0);
}

TEST(BuildBoundariesTest, Errors) {
  Drawing d;
  d.outlines.push_back({Square(10)});
  d.cuts.push_back({{2, 2}, {2, 12}, {4, 12}, {4, 2}});
  absl::Status s = BuildBoundaries(d, 3).status();
  EXPECT_THAT(s.message(), HasSubstr("drawing 3, cut 1 leaves the shape at (2, 10)"));

  d.cuts = {{{20, 20}, {30, 30}}};
  EXPECT_THAT(BuildBoundaries(d, 1).status().message(), HasSubstr("cut 1 lies outside the shape"));

  d.cuts = {{{2, 2}, {8, 2}}, {{4, 2}, {6, 2}}};
  EXPECT_THAT(BuildBoundaries(d, 1).status().message(), HasSubstr("runs along"));

  d.cuts = {{{0, 0}, {10, 0}}};
  EXPECT_THAT(BuildBoundaries(d, 1).status().message(), HasSubstr("runs along outline 1"));

  d.cuts.clear();
  d.outlines.push_back({{{5, 5}, {15, 5}, {15, 15}, {5, 15}}});
  EXPECT_THAT(BuildBoundaries(d, 2).status().message(),
              HasSubstr("drawing 2: outline 1 and outline 2 touch or cross at"));

  Drawing bow{{Outline{{{0, 0}, {10, 10}, {10, 0}, {0, 10}}}}};
  EXPECT_THAT(BuildBoundaries(bow, 4).status().message(),
              HasSubstr("drawing 4: outline crosses itself at (5, 5)"));
}

TEST(BuildBoundariesTest, CrossingCutsSplitIntoFour) {
  Drawing d;
  d.outlines.push_back({Square(10)});
  d.cuts.push_back({{-1, 5}, {11, 5}});
  d.cuts.push_back({{5, -1}, {5, 11}});
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, 1);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_EQ(g->equivalence.components, 4);
  EXPECT_EQ(g->bi_directed_edges, 4);
}

}  // namespace
}  // namespace inbetween::solver
