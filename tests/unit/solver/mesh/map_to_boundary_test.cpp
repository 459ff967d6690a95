// Tests for the injective mapping: convex (Tutte) and non-convex (barrier) targets land exactly
// on the boundary with no inverted triangle; impossible targets fail instead of folding.
#include "solver/mesh/map_to_boundary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

#include "solver/geometry/correspondence.h"
#include "solver/geometry/polygon.h"
#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/split_boundary_chords.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

Points Square() { return {{0, 0}, {100, 0}, {100, 100}, {0, 100}}; }

Points Hexagon() {
  Points p;
  for (int i = 0; i < 6; ++i)
    p.emplace_back(60 + 55 * std::cos(i * M_PI / 3), 60 + 55 * std::sin(i * M_PI / 3));
  return p;
}

Points Bar() { return {{0, 0}, {141.4, 0}, {141.4, 30}, {0, 30}}; }

// Annulus sector of `turns` * 180 degrees, radii 30 and 60, positive orientation.
Points Arch(double turns = 1.0) {
  Points p;
  const int k = static_cast<int>(40 * turns);
  for (int i = 0; i <= k; ++i) {
    const double a = turns * M_PI * i / k;
    p.emplace_back(80 - 60 * std::cos(a), 100 - 60 * std::sin(a));
  }
  for (int i = k; i >= 0; --i) {
    const double a = turns * M_PI * i / k;
    p.emplace_back(80 - 30 * std::cos(a), 100 - 30 * std::sin(a));
  }
  if (PolygonSignedArea(p) < 0) std::reverse(p.begin(), p.end());
  return p;
}

struct MapCase {
  Points source;
  std::vector<Triangle> triangles;
  std::vector<int> boundary;
  Points target;
};

// Mesh of the first outline, boundary target from the second (no boundary Steiner points: the
// size bound is generous relative to the boundary spacing).
MapCase Make(const Points& from, const Points& to, int n) {
  CorrespondenceOptions c;
  c.vertices = n;
  absl::StatusOr<Correspondence> corr =
      ComputeCorrespondence({Drawing{{Outline{from}}}, Drawing{{Outline{to}}}}, c);
  EXPECT_TRUE(corr.ok()) << corr.status();
  absl::StatusOr<PolygonTriangulation> tri = CgalTriangulate(corr->boundaries[0], {});
  EXPECT_TRUE(tri.ok()) << tri.status();
  EXPECT_TRUE(tri->boundary_steiner.empty());
  MapCase s;
  s.source = tri->vertices;
  s.triangles = tri->triangles;
  std::vector<bool> is_boundary(s.source.size(), false);
  for (int i = 0; i < n; ++i) s.boundary.push_back(i), is_boundary[i] = true;
  SplitBoundaryChords(&s.source, &s.triangles, &is_boundary);
  s.target = corr->boundaries[1];
  return s;
}

void ExpectInjectiveAndExact(const MapCase& s, const Points& x) {
  EXPECT_EQ(CountInverted(s.triangles, x), 0);
  for (size_t k = 0; k < s.boundary.size(); ++k) EXPECT_EQ(x[s.boundary[k]], s.target[k]);
}

TEST(MapToBoundaryTest, SquareToHexagonUsesTutte) {
  const MapCase s = Make(Square(), Hexagon(), 64);
  MapToBoundaryReport report;
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, {}, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_TRUE(report.tutte);
  EXPECT_GE(report.energy, 4.0);
}

TEST(MapToBoundaryTest, BarToArchNonConvexTutteStart) {
  const MapCase s = Make(Bar(), Arch(), 96);
  MapToBoundaryReport report;
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, {}, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_TRUE(report.tutte);  // the mean-value embedding folds nothing here: no pull needed
  EXPECT_EQ(report.stages, 0);
  EXPECT_LT(report.energy, 10.0);
}

TEST(MapToBoundaryTest, BarToArchNonConvex) {
  const MapCase s = Make(Bar(), Arch(), 96);
  MapToBoundaryReport report;
  MapToBoundaryOptions options;
  options.tutte_first_always = false;  // the progressive pull on its own
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, options, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_FALSE(report.tutte);
  EXPECT_GT(report.stages, 0);
  EXPECT_LT(report.energy, 10.0);  // bending a bar is a mild distortion
}

TEST(MapToBoundaryTest, LongBarToThreeQuarterRing) {
  // Mid-line length of a 270-degree sector: 1.5 * pi * 45 ~ 212.
  const Points bar = {{0, 0}, {212, 0}, {212, 30}, {0, 30}};
  const MapCase s = Make(bar, Arch(1.5), 128);
  MapToBoundaryReport report;
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, {}, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_LT(report.energy, 50.0);  // stronger bending than the half ring
}

TEST(MapToBoundaryTest, ArchToBarNonConvexSource) {
  const MapCase s = Make(Arch(), Bar(), 96);
  absl::StatusOr<Points> x = MapToBoundary(s.source, s.triangles, s.boundary, s.target);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
}

TEST(MapToBoundaryTest, AffineImageStartsFromTheAffineMap) {
  // A non-convex arch onto a rotated, sheared, scaled copy of itself: the pull starts from the
  // least-squares affine fit of the boundaries, which is exact here, so no stage is needed and
  // every vertex lands where the affine map puts it.
  MapCase s = Make(Arch(), Arch(), 96);
  Eigen::Matrix2d map;
  map << 1.2 * std::cos(0.7), -std::sin(0.7), 0.3 + std::sin(0.7), 0.8 * std::cos(0.7);
  ASSERT_GT(map.determinant(), 0.0);
  auto affine = [&](const Point& p) { return Point(map * p + Point(40, -25)); };
  for (size_t k = 0; k < s.boundary.size(); ++k) s.target[k] = affine(s.source[s.boundary[k]]);
  MapToBoundaryOptions options;
  options.tutte_first_always = false;
  MapToBoundaryReport report;
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, options, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_FALSE(report.tutte);
  EXPECT_EQ(report.stages, 0);
  for (size_t v = 0; v < s.source.size(); ++v) {
    EXPECT_LT(((*x)[v] - affine(s.source[v])).norm(), 1e-6) << v;
  }
}

TEST(MapToBoundaryTest, ImpossibleTargetFailsWithoutFolding) {
  MapCase s = Make(Square(), Hexagon(), 32);
  std::reverse(s.target.begin() + 1, s.target.end());  // mirror: would need every triangle flipped
  MapToBoundaryOptions options;
  options.max_iterations = 150;
  absl::StatusOr<Points> x = MapToBoundary(s.source, s.triangles, s.boundary, s.target, options);
  ASSERT_FALSE(x.ok());
  EXPECT_EQ(x.status().code(), absl::StatusCode::kFailedPrecondition);
}

TEST(MapToBoundaryTest, Cancelled) {
  const MapCase s = Make(Bar(), Arch(), 48);
  CancelToken cancel;
  cancel.Cancel();
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, {}, &cancel);
  EXPECT_EQ(x.status().code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace inbetween::solver
