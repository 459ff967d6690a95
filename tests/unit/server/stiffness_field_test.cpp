// StiffnessPerTriangle: centroid-in-region in drawing 1, later regions win, default 1.
#include "server/stiffness_field.h"

#include <gtest/gtest.h>

#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

solver::Multimesh UnitSquareMesh() {
  solver::Multimesh mesh;
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};  // centroids (2/3, 1/3) and (1/3, 2/3)
  mesh.shapes = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
  return mesh;
}

v1::StiffnessRegion Region(double x0, double y0, double size, double kappa) {
  v1::StiffnessRegion region;
  *region.mutable_polygon() = SquareOutline(x0, y0, size).polyline();
  region.set_kappa(kappa);
  return region;
}

TEST(StiffnessFieldTest, NoRegionsIsEmpty) {
  EXPECT_TRUE(StiffnessPerTriangle(UnitSquareMesh(), {}).empty());
}

TEST(StiffnessFieldTest, CentroidInsideGetsTheRegionsKappaLaterRegionsWin) {
  google::protobuf::RepeatedPtrField<v1::StiffnessRegion> regions;
  *regions.Add() = Region(0.5, 0, 0.5, 5);  // holds the first centroid only
  EXPECT_EQ(StiffnessPerTriangle(UnitSquareMesh(), regions), (std::vector<double>{5, 1}));
  *regions.Add() = Region(-1, -1, 3, 7);  // holds both
  EXPECT_EQ(StiffnessPerTriangle(UnitSquareMesh(), regions), (std::vector<double>{7, 7}));
}

}  // namespace
}  // namespace inbetween::server::testing
