// Tests client/render/boundary_loops.cpp: loop count, orientation (outer positive, holes
// negative), separate components, touching components and bad orientation.
#include "client/render/boundary_loops.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

using testing::OneFrame;
using testing::OrientPositive;

// Every boundary edge of the mesh is used exactly once by the loops.
void ExpectLoopsCoverBoundary(const FrameSet& set, const std::vector<Loop>& loops) {
  std::multiset<std::pair<int, int>> directed;
  for (const auto& t : set.triangles) {
    for (int i = 0; i < 3; ++i) directed.insert({t[i], t[(i + 1) % 3]});
  }
  std::multiset<std::pair<int, int>> boundary;
  for (const auto& [a, b] : directed) {
    if (!directed.count({b, a})) boundary.insert({a, b});
  }
  std::multiset<std::pair<int, int>> from_loops;
  for (const Loop& loop : loops) {
    for (size_t i = 0; i < loop.size(); ++i)
      from_loops.insert({loop[i], loop[(i + 1) % loop.size()]});
  }
  EXPECT_EQ(from_loops, boundary);
}

TEST(BoundaryLoopsTest, SquareWithHoleHasTwoLoopsOfOppositeOrientation) {
  const FrameSet set = testing::SquareWithHole();
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops(set.triangles);
  ASSERT_TRUE(loops.ok()) << loops.status();
  ASSERT_EQ(loops->size(), 2u);
  std::vector<double> areas;
  for (const Loop& loop : *loops) {
    EXPECT_EQ(loop.size(), 4u);
    areas.push_back(LoopSignedArea(loop, set.frames[0].vertices));
  }
  std::sort(areas.begin(), areas.end());
  EXPECT_DOUBLE_EQ(areas[0], -16.0);  // the hole, 4 x 4, against the triangles' orientation
  EXPECT_DOUBLE_EQ(areas[1], 100.0);  // the outside, 10 x 10, with it
  ExpectLoopsCoverBoundary(set, *loops);
}

TEST(BoundaryLoopsTest, TwoComponentsGiveTwoPositiveLoops) {
  const FrameSet set = testing::TwoSquares();
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops(set.triangles);
  ASSERT_TRUE(loops.ok()) << loops.status();
  ASSERT_EQ(loops->size(), 2u);
  for (const Loop& loop : *loops) {
    EXPECT_EQ(loop.size(), 4u);
    EXPECT_DOUBLE_EQ(LoopSignedArea(loop, set.frames[0].vertices), 1.0);
  }
  ExpectLoopsCoverBoundary(set, *loops);
}

TEST(BoundaryLoopsTest, ComponentsTouchingAtAVertexStaySeparateLoops) {
  // Two triangles sharing only vertex 2 (a bow tie).
  std::vector<Vertex> v = {{0, 0}, {2, 0}, {1, 1}, {0, 2}, {2, 2}};
  std::vector<std::array<int, 3>> tris = {{0, 1, 2}, {2, 4, 3}};
  OrientPositive(tris, v);
  const FrameSet set = OneFrame(v, tris);
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops(set.triangles);
  ASSERT_TRUE(loops.ok()) << loops.status();
  ASSERT_EQ(loops->size(), 2u);
  for (const Loop& loop : *loops) {
    EXPECT_EQ(loop.size(), 3u);
    EXPECT_GT(LoopSignedArea(loop, v), 0);
  }
  ExpectLoopsCoverBoundary(set, *loops);
}

TEST(BoundaryLoopsTest, RingLoopsFollowTheFanAndAreDeterministic) {
  auto [v, tris] = testing::Ring(24, 3, 1);
  absl::StatusOr<std::vector<Loop>> a = BoundaryLoops(tris);
  absl::StatusOr<std::vector<Loop>> b = BoundaryLoops(tris);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(*a, *b);
  ASSERT_EQ(a->size(), 2u);
  EXPECT_EQ((*a)[0].size(), 24u);
  EXPECT_EQ((*a)[1].size(), 24u);
  for (const Loop& loop : *a) {
    const bool outer = loop[0] < 24;  // vertices 0..23 are the outer circle
    EXPECT_EQ(LoopSignedArea(loop, v) > 0, outer);
    for (int i : loop) EXPECT_EQ(i < 24, outer);  // a loop never jumps between the circles
  }
  ExpectLoopsCoverBoundary(OneFrame(v, tris), *a);
}

TEST(BoundaryLoopsTest, SingleTriangleStartsAtItsFirstEdge) {
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops({{0, 1, 2}});
  ASSERT_TRUE(loops.ok());
  EXPECT_EQ(*loops, (std::vector<Loop>{{0, 1, 2}}));
}

TEST(BoundaryLoopsTest, EmptyMeshHasNoLoops) {
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops({});
  ASSERT_TRUE(loops.ok());
  EXPECT_TRUE(loops->empty());
}

TEST(BoundaryLoopsTest, InconsistentOrientationIsAnErrorNamingTheTriangles) {
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops({{0, 1, 2}, {0, 1, 3}});
  ASSERT_FALSE(loops.ok());
  EXPECT_EQ(loops.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(loops.status().message().find("triangles[0] and triangles[1]"), std::string::npos)
      << loops.status();
  EXPECT_NE(loops.status().message().find("0->1"), std::string::npos);
}

TEST(BoundaryLoopsTest, RepeatedVertexIsAnError) {
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops({{0, 1, 2}, {3, 3, 4}});
  ASSERT_FALSE(loops.ok());
  EXPECT_NE(loops.status().message().find("triangles[1] repeats a vertex"), std::string::npos);
}

}  // namespace
}  // namespace inbetween::render
