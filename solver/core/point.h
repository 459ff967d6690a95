// The plane's point type, shared by every solver stage.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace inbetween::solver {

using Point = Eigen::Vector2d;
using Points = std::vector<Point>;

}  // namespace inbetween::solver
