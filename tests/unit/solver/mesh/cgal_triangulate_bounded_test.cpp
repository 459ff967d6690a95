// Mesh refinement is bounded (TriangulateOptions::max_vertices, and no point closer than 1e-7 of
// the drawing's size to its neighbours): a spike 3.5e-10 wide made CGAL's Delaunay refinement run
// for as long as libFuzzer let it (mesh_fuzz finding, build/fuzz/artifacts/mesh_fuzz/
// timeout-659d0520…); it was then RESOURCE_EXHAUSTED after 20000 vertices and is now refused at
// once, naming the place (cusps like it crashed CGAL on real icons: tests/e2e/cli_icons_test.sh).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "solver/geometry/primitives.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/cgal_triangulate.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

// BuildMultimesh of drawing a and its image b: refused as a cusp or nearly touching boundaries
// in drawing 1 (its message, for more checks).
std::string ExpectRefusedAsNearlyTouching(const Points& a, const Points& b,
                                          const MultimeshOptions& options) {
  Drawing da, db;
  da.outlines = {{a}};
  db.outlines = {{b}};
  absl::StatusOr<Multimesh> m = BuildMultimesh({da, db}, options);
  EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument) << m.status();
  EXPECT_THAT(m.status().message(),
              HasSubstr("drawing 1: triangulate: the drawing has a cusp or boundaries that nearly "
                        "touch near ("));
  return std::string(m.status().message());
}

// The fuzzer's input decoded (tests/fuzz/mesh_fuzz.cpp): a triangle-like outline whose vertex 2
// is a spike 3.5e-10 below the edge it folds back along; drawing 2 is its affine image.
TEST(CgalTriangulateBoundedTest, ThinSpikeIsRefusedInsteadOfRefinedForever) {
  const Points a = {{2, 30}, {1, 0}, {0, -3.5e-10}, {20, 0}};
  Points b;
  for (const Point& p : a) b.emplace_back(0.5 * (p.x() - 0.5 * p.y()) + 5, 0.5 * p.y() - 3);
  MultimeshOptions options;
  options.max_mesh_vertices = 20000;
  ExpectRefusedAsNearlyTouching(a, b, options);
}

// Another fuzzer input (build/fuzz/artifacts/mesh_fuzz/crash-5252cc03…, decoded): a needle from
// (24, 0) whose two far corners are 2.75e-9 apart. CGAL's edge refinement failed an internal
// assertion on it ("n == zone.fh"), which came back as INTERNAL; the input's spacing is now
// checked first.
TEST(CgalTriangulateBoundedTest, CornersNearlyTouchingAreRefusedBeforeTheMesherSeesThem) {
  Points a = {{24 + 2.75e-9, 24 + 2.75e-9}, {24, 0}, {24 + 2.75e-9, 24}, {30, 3}};
  if (PolygonSignedArea2(a) < 0) std::reverse(a.begin(), a.end());
  Points b;
  for (const Point& p : a) {
    const Point s(0.6 * (p.x() - 0.5 * p.y()), 0.6 * p.y());
    b.emplace_back(std::cos(0.5) * s.x() - std::sin(0.5) * s.y() + 5,
                   std::sin(0.5) * s.x() + std::cos(0.5) * s.y() - 3);
  }
  MultimeshOptions options;  // the harness's
  options.boundary_vertices = 8;
  options.max_mesh_vertices = 300;
  options.max_map_iterations = 200;
  EXPECT_THAT(ExpectRefusedAsNearlyTouching(a, b, options), HasSubstr("apart"));
  // The polygon alone, by the polygon triangulator: the same answer.
  TriangulateOptions t;
  t.max_edge = 2.0;
  absl::StatusOr<PolygonTriangulation> p = CgalTriangulate(a, t);
  EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument) << p.status();
}

// A boundary segment shorter than the refinement's own spacing (1e-7 of the diagonal) where a
// straight side meets a curve, as in the icon filetype-scss (its points, moved to the origin):
// it meshes, above and below the side. The check before the mesher refused it at 1e-7 of the
// diagonal and takes 1e-8 now (the fuzz input it is there for: 8e-11).
TEST(CgalTriangulateBoundedTest, TinySegmentWhereASideMeetsACurveStillMeshes) {
  const Point a(0.764, 0), b(0.764 + 5.569e-7, 1.3868e-6), c(1.4245689139, 0.5181232773);
  for (const double side : {1.0, -1.0}) {
    // Diagonal 17.7: the segment (1.49e-6) is 8.4e-8 of it.
    Points p = {{-8, 0}, a, b, c, {c.x(), side * 15}, {-8, side * 15}};
    if (side < 0) std::reverse(p.begin(), p.end());
    TriangulateOptions t;
    t.max_edge = 1.0;
    absl::StatusOr<PolygonTriangulation> mesh = CgalTriangulate(p, t);
    ASSERT_TRUE(mesh.ok()) << side << ": " << mesh.status();
    EXPECT_GT(mesh->triangles.size(), 10u);
  }
}

TEST(CgalTriangulateBoundedTest, OrdinaryPolygonMeshesWithinTheBound) {
  const Points square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  TriangulateOptions options;
  options.max_edge = 1.0;
  options.max_vertices = 5000;
  absl::StatusOr<PolygonTriangulation> t = CgalTriangulate(square, options);
  ASSERT_TRUE(t.ok()) << t.status();
  EXPECT_GT(t->vertices.size(), 50u);
  options.max_vertices = 20;  // the same refinement needs more
  EXPECT_EQ(CgalTriangulate(square, options).status().code(), absl::StatusCode::kResourceExhausted);
}

}  // namespace
}  // namespace inbetween::solver
