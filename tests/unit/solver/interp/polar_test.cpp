// Closed-form 2x2 polar decomposition: M = R S, R closest rotation, S symmetric.
#include "solver/interp/polar.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <random>

namespace inbetween::solver {
namespace {

TEST(InterpPolarTest, DecomposesAndIsClosest) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Matrix2d m;
    m << u(rng), u(rng), u(rng), u(rng);
    const PolarDecomposition p = Polar(m);
    EXPECT_LT((p.rotation * p.stretch - m).norm(), 1e-12);
    EXPECT_EQ(p.stretch(0, 1), p.stretch(1, 0));
    EXPECT_NEAR(p.rotation.determinant(), 1.0, 1e-14);
    EXPECT_GT(p.angle, -std::numbers::pi);
    EXPECT_LE(p.angle, std::numbers::pi);
    EXPECT_LT((ClosestRotation(m) - p.rotation).norm(), 1e-12);
    if (m.determinant() > 0) EXPECT_GT(p.stretch.determinant(), 0.0);
    // No sampled rotation is closer.
    const double best = (m - p.rotation).squaredNorm();
    for (int k = 0; k < 360; ++k) {
      EXPECT_GE((m - RotationMatrix(k * std::numbers::pi / 180)).squaredNorm(), best - 1e-12);
    }
  }
}

TEST(InterpPolarTest, DegenerateAndExactCases) {
  EXPECT_EQ(ClosestRotation(Eigen::Matrix2d::Zero()), Eigen::Matrix2d::Identity());
  EXPECT_EQ(ClosestRotationAngle(Eigen::Matrix2d::Zero()), 0.0);
  EXPECT_EQ(Polar(-Eigen::Matrix2d::Identity()).angle, std::numbers::pi);
  const Eigen::Matrix2d r = RotationMatrix(2.0) * 3.0;
  EXPECT_NEAR(Polar(r).angle, 2.0, 1e-14);
  EXPECT_LT((Polar(r).stretch - 3.0 * Eigen::Matrix2d::Identity()).norm(), 1e-14);
}

TEST(InterpPolarTest, UnwrapPicksTheClosestBranch) {
  constexpr double kPi = std::numbers::pi;
  EXPECT_NEAR(UnwrapAngle(-0.9 * kPi, 0.9 * kPi), 1.1 * kPi, 1e-14);
  EXPECT_NEAR(UnwrapAngle(0.5, 10 * kPi), 10 * kPi + 0.5, 1e-12);
  EXPECT_NEAR(UnwrapAngle(0.5, 0.0), 0.5, 0.0);
}

}  // namespace
}  // namespace inbetween::solver
