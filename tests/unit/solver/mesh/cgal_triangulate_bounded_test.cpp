// Mesh refinement is bounded (TriangulateOptions::max_vertices, and no point closer than 1e-7 of
// the drawing's size to its neighbours): a spike 3.5e-10 wide made CGAL's Delaunay refinement run
// for as long as libFuzzer let it (mesh_fuzz finding, build/fuzz/artifacts/mesh_fuzz/
// timeout-659d0520…); it was then RESOURCE_EXHAUSTED after 20000 vertices and is now refused at
// once, naming the place (cusps like it crashed CGAL on real icons: tests/e2e/cli_icons_test.sh).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/cgal_triangulate.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

// The fuzzer's input decoded (tests/fuzz/mesh_fuzz.cpp): a triangle-like outline whose vertex 2
// is a spike 3.5e-10 below the edge it folds back along; drawing 2 is its affine image.
TEST(CgalTriangulateBoundedTest, ThinSpikeIsRefusedInsteadOfRefinedForever) {
  const Points a = {{2, 30}, {1, 0}, {0, -3.5e-10}, {20, 0}};
  Points b;
  for (const Point& p : a) b.emplace_back(0.5 * (p.x() - 0.5 * p.y()) + 5, 0.5 * p.y() - 3);
  Drawing da, db;
  da.outlines = {{a}};
  db.outlines = {{b}};
  MultimeshOptions options;
  options.max_mesh_vertices = 20000;
  absl::StatusOr<Multimesh> m = BuildMultimesh({da, db}, options);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument) << m.status();
  EXPECT_THAT(m.status().message(),
              HasSubstr("drawing 1: triangulate: the drawing has a cusp or boundaries that nearly "
                        "touch near ("));
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
  EXPECT_EQ(CgalTriangulate(square, options).status().code(),
            absl::StatusCode::kResourceExhausted);
}

}  // namespace
}  // namespace inbetween::solver
