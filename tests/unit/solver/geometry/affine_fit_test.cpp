// Tests for the least-squares affine fit: an exact image recovered, noise averaged, and the fits
// it must refuse (collinear points, a reflection, no points).
#include "solver/geometry/affine_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

namespace inbetween::solver {
namespace {

std::vector<std::pair<Point, Point>> Image(const std::vector<Point>& from, const Affine& map) {
  std::vector<std::pair<Point, Point>> pairs;
  for (const Point& p : from) pairs.push_back({p, map(p)});
  return pairs;
}

TEST(AffineFitTest, RecoversAnExactImage) {
  const Affine map{Eigen::Matrix2d{{1.2, -0.25}, {0.35, 1.1}}, Point(30, -4)};
  const std::vector<Point> from = {{0, 0}, {16, 0}, {16, 16}, {0, 16}, {5, 9}};
  Affine fit;
  ASSERT_TRUE(FitAffine(Image(from, map), &fit));
  EXPECT_LT((fit.m - map.m).norm(), 1e-12);
  EXPECT_LT((fit.t - map.t).norm(), 1e-12);
}

TEST(AffineFitTest, AveragesNoise) {
  const Affine map{Eigen::Matrix2d{{0.8, 0.3}, {-0.2, 1.5}}, Point(-3, 7)};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coord(-10, 10), noise(-0.01, 0.01);
  std::vector<std::pair<Point, Point>> pairs;
  for (int k = 0; k < 400; ++k) {
    const Point p(coord(rng), coord(rng));
    pairs.push_back({p, map(p) + Point(noise(rng), noise(rng))});
  }
  Affine fit;
  ASSERT_TRUE(FitAffine(pairs, &fit));
  EXPECT_LT((fit.m - map.m).norm(), 1e-3);
  EXPECT_LT((fit.t - map.t).norm(), 1e-2);
}

TEST(AffineFitTest, RefusesCollinearPointsAReflectionAndNothing) {
  Affine fit;
  // Collinear, up to 1e-9 off the line over a length of 100: the map across them is noise.
  const std::vector<Point> line = {{0, 0}, {50, 1e-9}, {100, 0}, {25, -1e-9}};
  EXPECT_FALSE(FitAffine(Image(line, Affine{}), &fit));
  const Affine mirror{Eigen::Matrix2d{{-1, 0}, {0, 1}}, Point::Zero()};
  EXPECT_FALSE(FitAffine(Image({{0, 0}, {1, 0}, {0, 1}}, mirror), &fit));
  EXPECT_FALSE(FitAffine(std::vector<std::pair<Point, Point>>{}, &fit));
  EXPECT_TRUE(FitAffine(Image({{0, 0}, {1, 0}, {0, 1}}, Affine{}), &fit));
}

}  // namespace
}  // namespace inbetween::solver
