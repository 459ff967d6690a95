// BuildMultimesh on walking poses: a drawing the reference mesh cannot be pulled onto directly is
// reached from the map into a neighbouring key (build_multimesh.cpp, "start instead from").
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "solver/geometry/polygon.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"
#include "tests/unit/solver/mesh/walker_poses.h"

namespace inbetween::solver {
namespace {

MultimeshOptions WalkerMeshOptions() {
  // About 1.8k vertices, as in the comesh-shapes benchmark (S-Table 3's walking character).
  const Drawing pose = testing::WalkerPose(0);
  const Points& outline = pose.outlines[0].points;
  double perimeter = 0.0;
  Eigen::AlignedBox2d box;
  for (size_t i = 0; i < outline.size(); ++i) {
    perimeter += (outline[(i + 1) % outline.size()] - outline[i]).norm();
    box.extend(outline[i]);
  }
  const double area = std::abs(PolygonSignedArea(outline));
  const double h = 1.5 * std::sqrt(2.0 * area / (std::sqrt(3.0) * 1639));
  MultimeshOptions options;
  options.boundary_vertices = std::max(8, static_cast<int>(std::lround(perimeter / h)));
  options.max_edge_relative = h / box.diagonal().norm();
  return options;
}

TEST(BuildMultimeshChainTest, DistantPoseIsReachedThroughItsNeighbour) {
  // Pose 3 is not reachable from pose 0's mesh in one pull at this resolution; pose 2 is, and
  // pose 3 is reachable from pose 2's map.
  const std::vector<Drawing> drawings = {testing::WalkerPose(0), testing::WalkerPose(2),
                                         testing::WalkerPose(3)};
  absl::StatusOr<Multimesh> mesh = BuildMultimesh(drawings, WalkerMeshOptions());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  ASSERT_EQ(mesh->num_shapes(), 3);
  for (int s = 0; s < 3; ++s) {
    EXPECT_EQ(CountInverted(mesh->triangles, mesh->shapes[s]), 0) << "shape " << s + 1;
  }
}

}  // namespace
}  // namespace inbetween::solver
