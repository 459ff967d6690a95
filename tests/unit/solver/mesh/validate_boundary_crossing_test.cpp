// ValidateBoundaryDoesNotCross: with every triangle positive a map can still fold its boundary
// over itself (bootstrap-icons yin-yang's affine copy did, and was handed out as a mesh); the
// multimesh validator and BuildMultimesh's map now refuse that.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

TEST(ValidateBoundaryCrossingTest, OverlappingPositiveTrianglesAreRefusedWithThePlace) {
  // Two positive triangles whose edges cross: no triangle inverted, the shape not injective.
  const std::vector<Triangle> triangles = {{0, 1, 2}, {3, 4, 5}};
  const Points x = {{0, 0}, {2, 0}, {0, 2}, {0.5, 0.5}, {3, 1}, {1, 3}};
  ASSERT_EQ(CountInverted(triangles, x), 0);
  const absl::Status s = ValidateBoundaryDoesNotCross(triangles, x);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  EXPECT_THAT(s.message(), HasSubstr("cross near ("));

  Multimesh mesh;
  mesh.triangles = triangles;
  mesh.shapes = {{{0, 0}, {2, 0}, {0, 2}, {5, 5}, {7, 5}, {5, 7}}, x};
  const absl::Status m = ValidateMultimesh(mesh);
  EXPECT_EQ(m.code(), absl::StatusCode::kInvalidArgument) << m;
  EXPECT_THAT(m.message(), HasSubstr("multimesh shape 1: boundary edges"));
}

TEST(ValidateBoundaryCrossingTest, SeparateAndTouchingBoundariesPass) {
  const std::vector<Triangle> triangles = {{0, 1, 2}, {3, 4, 5}};
  // Apart.
  EXPECT_TRUE(
      ValidateBoundaryDoesNotCross(triangles, {{0, 0}, {1, 0}, {0, 1}, {5, 5}, {6, 5}, {5, 6}})
          .ok());
  // The two sides of a closed cut: distinct vertices at the same places, edges on top of each
  // other (collinear overlap and shared end points are not crossings).
  EXPECT_TRUE(
      ValidateBoundaryDoesNotCross(triangles, {{0, 0}, {1, 0}, {0, 1}, {1, 0}, {1, 1}, {0, 1}})
          .ok());
  // A square of four triangles around a centre: one loop, nothing crosses.
  EXPECT_TRUE(ValidateBoundaryDoesNotCross({{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}},
                                           {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}})
                  .ok());
}

}  // namespace
}  // namespace inbetween::solver
