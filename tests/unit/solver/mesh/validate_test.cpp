// Tests for the mesh validators.
#include "solver/mesh/validate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

Multimesh TwoTriangles() {
  Multimesh m;
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.shapes = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{0, 0}, {2, 0}, {2, 2}, {0, 2}}};
  m.boundary = {0, 1, 2, 3};
  return m;
}

TEST(ValidateTest, SignedAreaAndCount) {
  const Points x = {{0, 0}, {1, 0}, {0, 1}};
  EXPECT_DOUBLE_EQ(SignedArea2({0, 1, 2}, x), 1.0);
  EXPECT_DOUBLE_EQ(SignedArea2({0, 2, 1}, x), -1.0);
  EXPECT_EQ(CountInverted({{0, 1, 2}, {0, 2, 1}}, x), 1);
  EXPECT_EQ(CountInverted({{0, 1, 2}}, x, 2.0), 1);
}

TEST(ValidateTest, ValidMultimesh) { EXPECT_TRUE(ValidateMultimesh(TwoTriangles()).ok()); }

TEST(ValidateTest, InvertedTriangleNamesShapeAndTriangle) {
  Multimesh m = TwoTriangles();
  m.shapes[1][3] = {3, -1};  // folds triangle 1 in shape 1
  absl::Status s = ValidateMultimesh(m);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("shape 1 triangle 1 is inverted"));
}

TEST(ValidateTest, TopologyErrors) {
  Multimesh m = TwoTriangles();
  m.shapes[1].pop_back();
  EXPECT_THAT(ValidateMultimesh(m).message(), HasSubstr("shape 1 has 3 vertices"));
  m = TwoTriangles();
  m.triangles[0][2] = 7;
  EXPECT_THAT(ValidateMultimesh(m).message(), HasSubstr("triangle 0 has vertex index 7"));
}

}  // namespace
}  // namespace inbetween::solver
