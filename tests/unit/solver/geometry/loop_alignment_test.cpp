#include "solver/geometry/loop_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace inbetween::solver {
namespace {

constexpr double kPi = std::numbers::pi;

// The 400 x 100 bar (counter-clockwise from its bottom-left corner) and the same bar bent about
// its centre line into a half ring (outer arc 557 long, inner 243), its long sides sampled at
// `per_side` points.
Points Bar() { return {{0, 0}, {400, 0}, {400, 100}, {0, 100}}; }

Point BendPoint(const Point& p) {
  const double radius = 400.0 / kPi;
  const double phi = (p.x() - 200.0) / radius, r = radius + (p.y() - 50.0);
  return Point(200.0 + r * std::sin(phi), 50.0 - radius + r * std::cos(phi));
}

Points HalfRing(int per_side) {
  Points out;
  for (int k = 0; k < per_side; ++k) out.push_back(BendPoint(Point(400.0 * k / per_side, 0)));
  out.push_back(BendPoint(Point(400, 0)));
  out.push_back(BendPoint(Point(400, 100)));
  for (int k = 1; k < per_side; ++k) {
    out.push_back(BendPoint(Point(400.0 - 400.0 * k / per_side, 100)));
  }
  out.push_back(BendPoint(Point(0, 100)));
  // Positive orientation, as a loop with the drawing on its left.
  return out;
}

double Length(const Points& p) {
  double total = 0;
  for (size_t i = 0; i < p.size(); ++i) total += (p[(i + 1) % p.size()] - p[i]).norm();
  return total;
}

// Where the alignment puts fraction `u` of loop a on loop b (a fraction of b, wrapped).
double MapFraction(const LoopAlignment& al, double u) {
  size_t k = 0;
  while (k + 1 < al.a.size() && al.a[k + 1] <= u) ++k;
  const double a1 = k + 1 < al.a.size() ? al.a[k + 1] : 1.0;
  const double b1 = k + 1 < al.b.size() ? al.b[k + 1] : al.b[0] + 1.0;
  const double f = (u - al.a[k]) / (a1 - al.a[k]);
  const double b = al.b[k] + f * (b1 - al.b[k]);
  return b - std::floor(b);
}

Points Normalised(const Points& p) {
  Point lo = p[0], hi = p[0];
  for (const Point& q : p) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  Points out;
  for (const Point& q : p) out.push_back((q - 0.5 * (lo + hi)) / (hi - lo).norm());
  return out;
}

TEST(LoopAlignmentTest, BarCornersGoOntoTheHalfRingsCorners) {
  const Points bar = Bar();
  const Points ring = HalfRing(64);
  const double bar_length = Length(bar), ring_length = Length(ring);
  // Arc-length fractions of the corners in both loops: (0,0), (400,0), (400,100), (0,100).
  const double bar_corners[] = {0.0, 400.0 / bar_length, 500.0 / bar_length, 900.0 / bar_length};
  // The ring's corners: points 0, 64, 65 and the last (HalfRing).
  std::vector<double> ring_corners;
  double arc = 0;
  for (size_t i = 0; i < ring.size(); ++i) {
    if (i == 0 || i == 64 || i == 65 || i + 1 == ring.size()) {
      ring_corners.push_back(arc / ring_length);
    }
    arc += (ring[(i + 1) % ring.size()] - ring[i]).norm();
  }
  ASSERT_EQ(ring_corners.size(), 4u);
  const LoopAlignment al = AlignLoops(Normalised(bar), Normalised(ring), 0.0);
  for (int k = 0; k < 4; ++k) {
    const double got = MapFraction(al, bar_corners[k]);
    const double gap = std::abs(got - ring_corners[k]);
    EXPECT_LT(std::min(gap, 1.0 - gap), 1e-9) << "corner " << k;
  }
}

TEST(LoopAlignmentTest, MatchedPairsIncreaseAndCoverOneTurn) {
  const LoopAlignment al = AlignLoops(Normalised(Bar()), Normalised(HalfRing(40)), 0.3);
  ASSERT_FALSE(al.a.empty());
  EXPECT_EQ(al.a[0], 0.0);
  EXPECT_GE(al.b[0], 0.0);
  EXPECT_LT(al.b[0], 1.0);
  for (size_t k = 1; k < al.a.size(); ++k) {
    EXPECT_GT(al.a[k], al.a[k - 1]);
    EXPECT_GT(al.b[k], al.b[k - 1]);
  }
  EXPECT_LT(al.a.back(), 1.0);
  EXPECT_LT(al.b.back(), al.b[0] + 1.0);
}

TEST(LoopAlignmentTest, Deterministic) {
  const Points a = Normalised(Bar()), b = Normalised(HalfRing(50));
  const LoopAlignment first = AlignLoops(a, b, 0.1);
  const LoopAlignment second = AlignLoops(a, b, 0.1);
  EXPECT_EQ(first.a, second.a);
  EXPECT_EQ(first.b, second.b);
  EXPECT_EQ(first.cost, second.cost);
}

// A square against itself listed from another corner: corner onto corner, and of the four
// rotations the one the positions agree with (no turn).
TEST(LoopAlignmentTest, SymmetricShapePairsByPosition) {
  const Points square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const Points shifted = {{1, 1}, {0, 1}, {0, 0}, {1, 0}};
  const LoopAlignment al = AlignLoops(Normalised(square), Normalised(shifted), 0.0);
  // Square's (0, 0) is the shifted list's third point: half way round.
  EXPECT_NEAR(MapFraction(al, 0.0), 0.5, 1e-9);
  EXPECT_NEAR(MapFraction(al, 0.25), 0.75, 1e-9);
}

}  // namespace
}  // namespace inbetween::solver
