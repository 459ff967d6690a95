// The boundary sampling to the outline tolerance (BoundaryCorrespondenceOptions::tolerance):
// every drawing's loops lie within the tolerance of its outline, Hausdorff both ways; a rounded
// end gets about the fewest vertices that tolerance needs, not a power-of-two split of the even
// ones; an outline the even sampling already holds keeps it; and corners of one drawing closer
// together than the tolerance make one breakpoint, not a sliver interval.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "solver/geometry/boundary_correspondence.h"
#include "solver/geometry/graph_flow.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

constexpr double kTolerance = 1e-3;  // BuildMultimesh's default (MultimeshOptions)

double Diagonal(const Points& p) {
  Point lo = p[0], hi = p[0];
  for (const Point& q : p) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  return (hi - lo).norm();
}

double DistanceToLoop(const Points& loop, const Point& q) {
  double best = INFINITY;
  for (size_t i = 0; i < loop.size(); ++i) {
    best = std::min(best, DistanceToSegment(q, loop[i], loop[(i + 1) % loop.size()]));
  }
  return best;
}

// Points along the closed polyline at most `step` apart, its vertices included.
Points Dense(const Points& loop, double step) {
  Points out;
  for (size_t i = 0; i < loop.size(); ++i) {
    const Point a = loop[i], b = loop[(i + 1) % loop.size()];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 0; k < n; ++k) out.push_back(a + (b - a) * (static_cast<double>(k) / n));
  }
  return out;
}

// Hausdorff distance (both ways) between two closed polylines.
double Hausdorff(const Points& a, const Points& b, double step) {
  double worst = 0;
  for (const Point& q : Dense(a, step)) worst = std::max(worst, DistanceToLoop(b, q));
  for (const Point& q : Dense(b, step)) worst = std::max(worst, DistanceToLoop(a, q));
  return worst;
}

BoundaryCorrespondence Sample(const std::vector<Points>& outlines, double tolerance) {
  std::vector<BoundaryGraph> graphs;
  for (size_t d = 0; d < outlines.size(); ++d) {
    Drawing drawing;
    drawing.outlines.push_back(Outline{outlines[d]});
    absl::StatusOr<BoundaryGraph> g = BuildBoundaries(drawing, static_cast<int>(d) + 1);
    EXPECT_TRUE(g.ok()) << g.status();
    graphs.push_back(*std::move(g));
  }
  BoundaryCorrespondenceOptions options;
  options.tolerance = tolerance;
  options.alignment = BoundaryCorrespondenceOptions::Alignment::kFeatures;
  absl::StatusOr<BoundaryCorrespondence> bc = ComputeBoundaryCorrespondence(graphs, options);
  EXPECT_TRUE(bc.ok()) << bc.status();
  return bc.ok() ? *std::move(bc) : BoundaryCorrespondence{};
}

// A w x 2r bar with half-disc ends of radius r, each flattened into `arc` segments, counter-
// clockwise from the bottom left.
Points Capsule(double w, double r, int arc) {
  Points p;
  for (int k = 0; k <= arc; ++k) {  // right end, bottom to top
    const double a = -std::numbers::pi / 2 + std::numbers::pi * k / arc;
    p.emplace_back(w + r * std::cos(a), r + r * std::sin(a));
  }
  for (int k = 0; k <= arc; ++k) {  // left end, top to bottom
    const double a = std::numbers::pi / 2 + std::numbers::pi * k / arc;
    p.emplace_back(r * std::cos(a), r + r * std::sin(a));
  }
  return p;
}

// The fewest chords within `tol` of a circle of radius r that cover `angle` of it.
int FewestChords(double r, double tol, double angle) {
  return static_cast<int>(std::ceil(angle / (2 * std::acos(1 - tol / r))));
}

TEST(OutlineSamplingTest, RoundEndsGetAboutTheFewestVerticesTheToleranceNeeds) {
  // Two capsules of different lengths and end radii (the long side stretches): the even
  // sampling puts one or two vertices on each end, far outside the tolerance.
  const std::vector<Points> outlines = {Capsule(1000, 6, 90), Capsule(700, 9, 90)};
  const BoundaryCorrespondence bc = Sample(outlines, kTolerance);
  ASSERT_EQ(bc.num_loops(), 1);
  for (size_t d = 0; d < outlines.size(); ++d) {
    SCOPED_TRACE(::testing::Message() << "drawing " << d + 1);
    const Points& loop = bc.shapes[d][0];
    const double diagonal = Diagonal(outlines[d]);
    const double tol = kTolerance * diagonal;
    EXPECT_LE(Hausdorff(loop, outlines[d], 1e-2 * tol), tol * (1 + 1e-9));
    // Vertices on the ends (beyond the straight sides), against the chords the rounder end
    // needs, both ends (8): the pairing decides where the other drawing's vertices fall, so some
    // of them land on this one's ends too. At most 1.5x: halving each strayed chord at its
    // farthest point put 10 and 16 there.
    const double w = d == 0 ? 1000 : 700;
    int on_ends = 0;
    for (const Point& p : loop) on_ends += p.x() < -1e-9 || p.x() > w + 1e-9;
    const int fewest =
        2 * std::max(FewestChords(6, kTolerance * Diagonal(outlines[0]), std::numbers::pi),
                     FewestChords(9, kTolerance * Diagonal(outlines[1]), std::numbers::pi));
    EXPECT_LE(on_ends, fewest + fewest / 2);
  }
  EXPECT_LE(bc.achieved_tolerance, kTolerance * (1 + 1e-9));
}

TEST(OutlineSamplingTest, AnOutlineTheEvenSamplingHoldsKeepsIt) {
  // Polygons: the even sampling lies on them, so the tolerance changes nothing.
  const std::vector<Points> outlines = {{{0, 0}, {400, 0}, {400, 100}, {0, 100}},
                                        {{0, 0}, {300, 20}, {320, 140}, {10, 90}}};
  const BoundaryCorrespondence with = Sample(outlines, kTolerance);
  const BoundaryCorrespondence without = Sample(outlines, 0.0);
  EXPECT_EQ(with.shapes, without.shapes);
  EXPECT_EQ(with.num_vertices(), with.base_vertices);
}

TEST(OutlineSamplingTest, CornersANotchApartMakeOneBreakpoint) {
  // A square whose top right corner is cut by a 0.05-wide notch: two corners 0.07 apart, 5e-4
  // of the diagonal, inside the 1e-3 tolerance. Paired with a plain square.
  const Points notched = {{0, 0}, {100, 0}, {100, 99.95}, {99.95, 100}, {0, 100}};
  const Points square = {{10, 10}, {110, 10}, {110, 110}, {10, 110}};
  const BoundaryCorrespondence bc = Sample({notched, square}, kTolerance);
  for (int d = 0; d < 2; ++d) {
    const Points& loop = bc.shapes[d][0];
    double shortest = INFINITY;
    for (size_t i = 0; i < loop.size(); ++i) {
      shortest = std::min(shortest, (loop[(i + 1) % loop.size()] - loop[i]).norm());
    }
    EXPECT_GT(shortest, 1.0) << "drawing " << d + 1;
    const Points& outline = d == 0 ? notched : square;
    EXPECT_LE(Hausdorff(loop, outline, 1e-3), kTolerance * Diagonal(outline) * (1 + 1e-9));
  }
  // Without the tolerance both corners stay breakpoints (the legacy sampling).
  const BoundaryCorrespondence legacy = Sample({notched, square}, 0.0);
  const Points& loop = legacy.shapes[0][0];
  double shortest = INFINITY;
  for (size_t i = 0; i < loop.size(); ++i) {
    shortest = std::min(shortest, (loop[(i + 1) % loop.size()] - loop[i]).norm());
  }
  EXPECT_LT(shortest, 0.1);
}

}  // namespace
}  // namespace inbetween::solver
