// Arc-length morph of polylines: parameters, sampling, each path kept at its own vertices.
#include "solver/art/blend_paths.h"

#include <gtest/gtest.h>

#include "tests/unit/solver/art/art_test_helpers.h"

namespace inbetween::solver {
namespace {

TEST(ArtBlendPathsTest, ArcLengthParameters) {
  const Points l = {{0, 0}, {1, 0}, {1, 3}};
  EXPECT_EQ(ArcLengthParameters(l, false), (std::vector<double>{0, 0.25, 1}));
  const Points square = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  EXPECT_EQ(ArcLengthParameters(square, true), (std::vector<double>{0, 0.25, 0.5, 0.75}));
  EXPECT_EQ(ArcLengthParameters({{1, 1}, {1, 1}}, false), (std::vector<double>{0, 0}));
  const std::vector<double> params = ArcLengthParameters(square, true);
  EXPECT_EQ(PointAtParameter(square, true, params, 0.875), Point(0, 1));  // on the closing side
  EXPECT_EQ(PointAtParameter(l, false, ArcLengthParameters(l, false), 1.0), Point(1, 3));
}

TEST(ArtBlendPathsTest, MidwayBetweenPolylinesOfDifferentCounts) {
  const Points a = {{0, 0}, {2, 0}};
  const Points b = {{0, 2}, {1, 3}, {2, 2}};
  const Points m = BlendPaths({a, b}, false, {0.5, 0.5}, 1e-9);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0], Point(0, 1));
  EXPECT_EQ(m[1], Point(1, 1.5));
  EXPECT_EQ(m[2], Point(2, 1));
}

TEST(ArtBlendPathsTest, EachPathKeptAtWeightOne) {
  const Points a = {{0, 0}, {4, 0}, {4, 1}, {0, 3}};
  const Points b = {{0, 0}, {1, 1}, {2, 0}, {3, 1}, {2, 5}, {1, 3}};
  for (bool closed : {false, true}) {
    const Points m = BlendPaths({a, b}, closed, {1.0, 0.0}, 1e-9);
    EXPECT_EQ(m.size(), closed ? 9u : 8u);  // shared parameter 0 (and 1 when open)
    for (const Point& p : a) {
      EXPECT_NE(std::find(m.begin(), m.end(), p), m.end()) << p.transpose();
    }
    for (const Point& p : m) EXPECT_LT(art_test::DistanceToPolyline(a, closed, p), 1e-12);
  }
}

TEST(ArtBlendPathsTest, ClosedSquaresMorphToTheMiddleSquare) {
  const Points a = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  const Points b = {{1, 1}, {5, 1}, {5, 5}, {1, 5}};
  const Points m = BlendPaths({a, b}, true, {0.25, 0.75}, 1e-9);
  const Points expected = {{0.75, 0.75}, {4.25, 0.75}, {4.25, 4.25}, {0.75, 4.25}};
  EXPECT_EQ(m, expected);
}

TEST(ArtBlendPathsTest, ClosedPathsAreAlignedToTheReferencesStartAndDirection) {
  const Points square = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};
  // Started at the third corner; drawn the other way; started half-way along a side.
  EXPECT_EQ(AlignClosedPath(square, {{4, 4}, {0, 4}, {0, 0}, {4, 0}}), square);
  EXPECT_EQ(AlignClosedPath(square, {{0, 0}, {0, 4}, {4, 4}, {4, 0}}), square);
  const Points octagon_like = {{2, 0}, {4, 0}, {4, 4}, {0, 4}, {0, 0}};
  EXPECT_EQ(AlignClosedPath(square, octagon_like),
            (Points{{0, 0}, {2, 0}, {4, 0}, {4, 4}, {0, 4}}));
  // A start between the path's own vertices gets a vertex there: same point set.
  const Points shifted = {{1, 1}, {5, 1}, {5, 5}, {1, 5}};
  const Points diamond = {{3, 0}, {6, 3}, {3, 6}, {0, 3}};
  const Points aligned = AlignClosedPath(shifted, diamond);
  EXPECT_EQ(aligned.size(), 5u);
  for (const Point& p : diamond) {
    EXPECT_NE(std::find(aligned.begin(), aligned.end(), p), aligned.end()) << p.transpose();
  }
  EXPECT_LT((aligned[0] - Point(1.5, 1.5)).norm(), 0.2) << aligned[0].transpose();
  // Too short to align: as given.
  EXPECT_EQ(AlignClosedPath(square, {{0, 0}, {1, 1}}), (Points{{0, 0}, {1, 1}}));
}

}  // namespace
}  // namespace inbetween::solver
