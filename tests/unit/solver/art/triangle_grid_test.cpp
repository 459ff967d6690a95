// TriangleGrid answers as brute force does: containing and nearest triangle, segment candidates.
#include "solver/art/triangle_grid.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "tests/unit/solver/art/art_test_helpers.h"

namespace inbetween::solver {
namespace {

using art_test::JitteredGrid;

TEST(ArtTriangleGridTest, ContainingAndNearestMatchBruteForce) {
  const Multimesh mesh = JitteredGrid(12, 7, 0.3);
  const Points& x = mesh.shapes[0];
  for (double per_cell : {0.5, 2.0, 50.0}) {
    const TriangleGrid grid(mesh.triangles, x, per_cell);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> ux(-4.0, 16.0), uy(-3.0, 10.0);
    for (int k = 0; k < 500; ++k) {
      const Point p(ux(rng), uy(rng));
      double best = std::numeric_limits<double>::infinity();
      bool inside = false;
      for (const Triangle& t : mesh.triangles) {
        best = std::min(best, DistanceToTriangle(x[t[0]], x[t[1]], x[t[2]], p));
        inside = inside || Barycentric(x[t[0]], x[t[1]], x[t[2]], p).minCoeff() >= 0.0;
      }
      const int c = grid.Containing(p, 0.0);
      EXPECT_EQ(c >= 0, inside) << p.transpose();
      if (c >= 0) {
        const Triangle& t = mesh.triangles[c];
        EXPECT_GE(Barycentric(x[t[0]], x[t[1]], x[t[2]], p).minCoeff(), 0.0);
      }
      double d = -1.0;
      const int n = grid.Nearest(p, &d);
      ASSERT_GE(n, 0);
      EXPECT_EQ(d, best) << p.transpose();
    }
  }
}

TEST(ArtTriangleGridTest, AlongSegmentHoldsEveryCrossedTriangle) {
  const Multimesh mesh = JitteredGrid(10, 10, 0.3);
  const Points& x = mesh.shapes[0];
  const TriangleGrid grid(mesh.triangles, x);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 12.0);
  for (int k = 0; k < 100; ++k) {
    const Point p(u(rng), u(rng)), q(u(rng), u(rng));
    const std::vector<int> candidates = grid.AlongSegment(p, q);
    // Every triangle holding a point of pq (sampled densely) is a candidate.
    for (int s = 0; s <= 200; ++s) {
      const Point at = p + (s / 200.0) * (q - p);
      for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        if (Barycentric(x[tri[0]], x[tri[1]], x[tri[2]], at).minCoeff() < 0.0) continue;
        EXPECT_TRUE(std::binary_search(candidates.begin(), candidates.end(), static_cast<int>(t)));
      }
    }
  }
}

}  // namespace
}  // namespace inbetween::solver
