// Tests for S-eq.1: ODT mesh energy value, gradient (finite differences), normalization.
#include "solver/comesh/odt_energy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "solver/geometry/primitives.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace inbetween::solver {
namespace {

Points Jittered(const Multimesh& m, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  Points x = m.shapes[0];
  for (Point& p : x) p += Point(u(rng), u(rng));
  return x;
}

TEST(OdtEnergyTest, TriangleValueIsAreaTimesSquaredEdgesOverTwelve) {
  const Point a(0, 0), b(2, 0), c(0, 1);
  EXPECT_NEAR(OdtTriangleEnergy(a, b, c), 1.0 * (4 + 1 + 5) / 12.0, 1e-15);
}

TEST(OdtEnergyTest, InvertedOrDegenerateIsInfinite) {
  EXPECT_TRUE(std::isinf(OdtTriangleEnergy(Point(0, 0), Point(0, 1), Point(1, 0))));
  EXPECT_TRUE(std::isinf(OdtTriangleEnergy(Point(0, 0), Point(1, 1), Point(2, 2))));
}

TEST(OdtEnergyTest, GradientMatchesFiniteDifferences) {
  const Multimesh m = testing::SquareGrid(5);
  const Points x = Jittered(m, 0.03, 7);
  Points g(x.size(), Point::Zero());
  OdtEnergy(m.triangles, x, &g);
  double err2 = 0.0, norm2 = 0.0;
  const double h = 1e-6;
  for (size_t v = 0; v < x.size(); ++v) {
    for (int c = 0; c < 2; ++c) {
      Points xp = x, xm = x;
      xp[v][c] += h;
      xm[v][c] -= h;
      const double fd = (OdtEnergy(m.triangles, xp) - OdtEnergy(m.triangles, xm)) / (2 * h);
      err2 += (fd - g[v][c]) * (fd - g[v][c]);
      norm2 += g[v][c] * g[v][c];
    }
  }
  EXPECT_LT(std::sqrt(err2 / norm2), 1e-5);
}

// S-eq.1 is our gradient times 3 / (8 Gamma_j) at interior vertices (see odt_energy.h).
TEST(OdtEnergyTest, InteriorGradientIsSupplementEquationOneRescaled) {
  const Multimesh m = testing::SquareGrid(4);
  const Points x = Jittered(m, 0.04, 3);
  Points g(x.size(), Point::Zero());
  OdtEnergy(m.triangles, x, &g);
  const int j = 2 * 5 + 2;  // interior vertex (2, 2) of the 5x5 grid
  Point seq1 = Point::Zero();
  double gamma = 0.0;
  for (const Triangle& t : m.triangles) {
    int k = 0;
    while (k < 3 && t[k] != j) ++k;
    if (k == 3) continue;
    const Point& b = x[t[(k + 1) % 3]];
    const Point& c = x[t[(k + 2) % 3]];
    const Point grad_area(0.5 * (b.y() - c.y()), 0.5 * (c.x() - b.x()));
    const double sum = (x[j] - b).squaredNorm() + (x[j] - c).squaredNorm();
    seq1 += grad_area * sum;
    gamma += 0.5 * SignedArea2(x[j], b, c);
  }
  seq1 /= 8.0 * gamma;
  EXPECT_NEAR((g[j] * 3.0 / (8.0 * gamma) - seq1).norm(), 0.0, 1e-12 * (1.0 + seq1.norm()));
}

TEST(OdtEnergyTest, NormalizedEnergyIsOneForEquilateralAndScaleInvariant) {
  const Point a(0, 0), b(1, 0), c(0.5, std::sqrt(3.0) / 2);
  const std::vector<Triangle> tris = {{0, 1, 2}};
  for (double s : {1e-3, 1.0, 250.0}) {
    const Points x = {s * a, s * b, s * c};
    EXPECT_NEAR(OdtEnergy(tris, x) / OdtNormalization(tris, x), 1.0, 1e-12);
  }
  // Right-isosceles grid: 2 / sqrt(3), independent of resolution.
  for (int k : {2, 8, 20}) {
    const Multimesh m = testing::SquareGrid(k);
    EXPECT_NEAR(OdtEnergy(m.triangles, m.shapes[0]) / OdtNormalization(m.triangles, m.shapes[0]),
                2.0 / std::sqrt(3.0), 1e-12);
  }
}

TEST(OdtEnergyTest, InvariantUnderRigidMotion) {
  const Multimesh m = testing::SquareGrid(4);
  const Points x = Jittered(m, 0.04, 11);
  const Points y = testing::Similar(x, 0.7, 1.0, Point(3, -2));
  EXPECT_NEAR(OdtEnergy(m.triangles, x), OdtEnergy(m.triangles, y), 1e-13);
}

}  // namespace
}  // namespace inbetween::solver
