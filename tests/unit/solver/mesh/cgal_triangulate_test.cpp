// Tests for the CGAL wrapper: positive triangles, boundary preserved, Steiner points reported.
#include "solver/mesh/cgal_triangulate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "solver/geometry/polygon.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

// Every boundary segment (with Steiner points inserted in order) is a mesh edge used once.
void ExpectBoundaryPreserved(const Points& boundary, const PolygonTriangulation& tri) {
  const int n = static_cast<int>(boundary.size());
  std::vector<int> order;
  size_t next = 0;
  for (int s = 0; s < n; ++s) {
    order.push_back(s);
    for (; next < tri.boundary_steiner.size() && tri.boundary_steiner[next].segment == s; ++next) {
      order.push_back(tri.boundary_steiner[next].vertex);
    }
  }
  std::map<std::pair<int, int>, int> directed;
  for (const Triangle& t : tri.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  int boundary_edges = 0;
  for (const auto& [e, count] : directed) {
    if (!directed.count({e.second, e.first})) ++boundary_edges;
  }
  EXPECT_EQ(boundary_edges, static_cast<int>(order.size()));
  for (size_t i = 0; i < order.size(); ++i) {
    const int a = order[i], b = order[(i + 1) % order.size()];
    EXPECT_EQ(directed.count({a, b}), 1u) << a << "->" << b;  // positive orientation
    EXPECT_EQ(directed.count({b, a}), 0u);
  }
  for (const BoundarySteiner& s : tri.boundary_steiner) {
    const Point expected = (1 - s.t) * boundary[s.segment] + s.t * boundary[(s.segment + 1) % n];
    EXPECT_LT((tri.vertices[s.vertex] - expected).norm(), 1e-9);
    EXPECT_GT(s.t, 0.0);
    EXPECT_LT(s.t, 1.0);
  }
}

double TotalArea(const PolygonTriangulation& tri) {
  double a = 0;
  for (const Triangle& t : tri.triangles) a += 0.5 * SignedArea2(t, tri.vertices);
  return a;
}

TEST(CgalTriangulateTest, SquareWithoutSizeBound) {
  const Points square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  absl::StatusOr<PolygonTriangulation> tri = CgalTriangulate(square);
  ASSERT_TRUE(tri.ok()) << tri.status();
  for (int i = 0; i < 4; ++i) EXPECT_EQ(tri->vertices[i], square[i]);
  EXPECT_EQ(CountInverted(tri->triangles, tri->vertices), 0);
  EXPECT_NEAR(TotalArea(*tri), 100.0, 1e-9);
  ExpectBoundaryPreserved(square, *tri);
}

TEST(CgalTriangulateTest, NonConvexWithSizeBoundAddsBoundarySteinerPoints) {
  const Points l = {{0, 0}, {30, 0}, {30, 10}, {10, 10}, {10, 30}, {0, 30}};
  TriangulateOptions options;
  options.max_edge = 3.0;
  absl::StatusOr<PolygonTriangulation> tri = CgalTriangulate(l, options);
  ASSERT_TRUE(tri.ok()) << tri.status();
  EXPECT_GT(tri->vertices.size(), 30u);
  EXPECT_FALSE(tri->boundary_steiner.empty());
  EXPECT_EQ(CountInverted(tri->triangles, tri->vertices), 0);
  EXPECT_NEAR(TotalArea(*tri), PolygonSignedArea(l), 1e-9);
  ExpectBoundaryPreserved(l, *tri);
  // Quality: no edge longer than the bound (up to CGAL's strictness).
  for (const Triangle& t : tri->triangles) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE((tri->vertices[t[k]] - tri->vertices[t[(k + 1) % 3]]).norm(), 3.0 + 1e-9);
    }
  }
}

TEST(CgalTriangulateTest, RejectsNegativeOrTinyInput) {
  EXPECT_FALSE(CgalTriangulate({{0, 0}, {1, 0}}).ok());
  EXPECT_EQ(CgalTriangulate({{0, 0}, {0, 1}, {1, 0}}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace inbetween::solver
