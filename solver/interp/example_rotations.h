// Per-triangle rotation/stretch split of every example relative to example 0 (Alexa, Cohen-Or,
// Levin 2000): A_it = D_it D_0t^{-1} = R(theta_it) S_it, with the angles theta_it unwrapped so
// that blending them, theta_t(w) = sum_i w_i theta_it, is meaningful:
//  - spatially: within one example, each triangle's angle is the branch closest to that of an
//    edge-adjacent triangle (breadth-first from the lowest-index triangle of each edge-connected
//    component), so a 180-degree turn is +pi or -pi for the whole shape, never a mix;
//  - across examples: the seed triangle's angle of example i is the branch closest to its angle
//    in example i-1 (example 0 is 0, so example 1 lies in (-pi, pi] relative to example 0), so
//    keys 0, 150, 300 degrees turn forward through 300 degrees.
// The angles depend only on the examples, so theta_t(w) is continuous in w and consecutive frames
// cannot jump between branches.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

struct ExampleRotations {
  std::vector<std::vector<double>> angles;              // [example][triangle], radians
  std::vector<std::vector<Eigen::Matrix2d>> stretches;  // [example][triangle], symmetric
};

// `shapes` share `triangles`; every triangle has positive area in every shape (not re-checked).
ExampleRotations ComputeExampleRotations(const std::vector<Triangle>& triangles,
                                         const std::vector<Points>& shapes);

// Edge-adjacent triangles of each triangle, ascending.
std::vector<std::vector<int>> TriangleAdjacency(const std::vector<Triangle>& triangles);

}  // namespace inbetween::solver
