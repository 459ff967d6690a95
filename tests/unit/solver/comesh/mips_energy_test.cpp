// Tests for S-eq.2 / S §6: MIPS sigma*, symmetry, transitivity, gradient (finite differences).
#include "solver/comesh/mips_energy.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>
#include <random>

#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace inbetween::solver {
namespace {

// A random positively oriented edge matrix with determinant bounded away from 0.
Eigen::Matrix2d RandomEdges(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (;;) {
    Eigen::Matrix2d m;
    m << u(rng), u(rng), u(rng), u(rng);
    if (m.determinant() > 0.05) return m;
  }
}

TEST(MipsEnergyTest, SigmaIsSingularValueRatioSum) {
  std::mt19937 rng(1);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Matrix2d p = RandomEdges(rng), q = RandomEdges(rng);
    const Eigen::Matrix2d f = q * p.inverse();
    const Eigen::Vector2d s = Eigen::JacobiSVD<Eigen::Matrix2d>(f).singularValues();
    const double expected = s[0] / s[1] + s[1] / s[0];
    EXPECT_NEAR(MipsSigma(p, q), expected, 1e-9 * expected);
    EXPECT_GE(MipsSigma(p, q), 2.0 - 1e-12);
  }
}

TEST(MipsEnergyTest, SigmaIsTwoForSimilarities) {
  std::mt19937 rng(2);
  const Eigen::Matrix2d p = RandomEdges(rng);
  Eigen::Matrix2d r;
  r << std::cos(1.1), -std::sin(1.1), std::sin(1.1), std::cos(1.1);
  EXPECT_NEAR(MipsSigma(p, 3.5 * r * p), 2.0, 1e-12);
}

TEST(MipsEnergyTest, SigmaIsSymmetric) {
  std::mt19937 rng(3);
  for (int i = 0; i < 500; ++i) {
    const Eigen::Matrix2d p = RandomEdges(rng), q = RandomEdges(rng);
    EXPECT_NEAR(MipsSigma(p, q), MipsSigma(q, p), 1e-10 * MipsSigma(p, q));
  }
}

TEST(MipsEnergyTest, TransitivityBound) {
  std::mt19937 rng(4);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Matrix2d a = RandomEdges(rng), b = RandomEdges(rng), c = RandomEdges(rng);
    EXPECT_LE(MipsSigma(a, c), MipsSigma(a, b) * MipsSigma(b, c) * (1.0 + 1e-12));
  }
}

TEST(MipsEnergyTest, InvertedOrDegenerateIsInfinite) {
  Eigen::Matrix2d p = Eigen::Matrix2d::Identity(), flipped, flat;
  flipped << 0, 1, 1, 0;
  flat << 1, 2, 1, 2;
  EXPECT_TRUE(std::isinf(MipsSigma(p, flipped)));
  EXPECT_TRUE(std::isinf(MipsSigma(flipped, p)));
  EXPECT_TRUE(std::isinf(MipsSigma(p, flat)));
  const std::array<Point, 3> ok = {Point(0, 0), Point(1, 0), Point(0, 1)};
  const std::array<Point, 3> bad = {Point(0, 0), Point(0, 1), Point(1, 0)};
  EXPECT_TRUE(std::isinf(MipsTriangleEnergy(ok, bad)));
  EXPECT_TRUE(std::isinf(MipsTriangleEnergy(bad, ok)));
}

TEST(MipsEnergyTest, TriangleEnergyIsSourceAreaTimesSigma) {
  const std::array<Point, 3> xi = {Point(0, 0), Point(2, 0), Point(0, 1)};
  const std::array<Point, 3> xj = {Point(1, 1), Point(2, 1.5), Point(0.5, 3)};
  Eigen::Matrix2d p, q;
  p.col(0) = xi[1] - xi[0];
  p.col(1) = xi[2] - xi[0];
  q.col(0) = xj[1] - xj[0];
  q.col(1) = xj[2] - xj[0];
  EXPECT_NEAR(MipsTriangleEnergy(xi, xj), 1.0 * MipsSigma(p, q), 1e-12);
}

TEST(MipsEnergyTest, GradientMatchesFiniteDifferences) {
  const Multimesh m = testing::SquareGrid(4);
  const Points xi = testing::SmoothlyDistorted(m.shapes[0], 0.08);
  const Points xj = testing::TutteHexagon(m);
  ASSERT_EQ(testing::CountNonPositive(m.triangles, xj), 0);
  Points gi(xi.size(), Point::Zero()), gj(xj.size(), Point::Zero());
  MipsEnergy(m.triangles, xi, xj, &gi, &gj);
  const double h = 1e-6;
  for (int side = 0; side < 2; ++side) {
    const Points& g = side == 0 ? gi : gj;
    double err2 = 0.0, norm2 = 0.0;
    for (size_t v = 0; v < xi.size(); ++v) {
      for (int c = 0; c < 2; ++c) {
        Points ap = side == 0 ? xi : xj, am = ap;
        ap[v][c] += h;
        am[v][c] -= h;
        const double fp =
            side == 0 ? MipsEnergy(m.triangles, ap, xj) : MipsEnergy(m.triangles, xi, ap);
        const double fm =
            side == 0 ? MipsEnergy(m.triangles, am, xj) : MipsEnergy(m.triangles, xi, am);
        const double fd = (fp - fm) / (2 * h);
        err2 += (fd - g[v][c]) * (fd - g[v][c]);
        norm2 += g[v][c] * g[v][c];
      }
    }
    EXPECT_LT(std::sqrt(err2 / norm2), 1e-5) << "shape " << side;
  }
}

TEST(MipsEnergyTest, SameShapeBothSidesAccumulates) {
  const Multimesh m = testing::SquareGrid(3);
  const Points x = testing::SmoothlyDistorted(m.shapes[0], 0.05);
  Points g(x.size(), Point::Zero());
  // C(X, X) = 2 * total area: its gradient vanishes at every interior vertex.
  EXPECT_NEAR(MipsEnergy(m.triangles, x, x, &g, &g), 2.0, 1e-12);
  EXPECT_NEAR(g[1 * 4 + 1].norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace inbetween::solver
