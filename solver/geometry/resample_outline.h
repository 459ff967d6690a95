// Arc-length resampling of a closed outline to a fixed vertex count, keeping its corners.
#pragma once

#include "solver/core/types.h"

namespace inbetween::solver {

struct ResampleOptions {
  // Vertices turning by more than this (degrees) are corners and kept exactly, when the vertex
  // budget allows; the remaining vertices are spread by arc length between corners.
  double corner_angle_degrees = 30.0;
};

// Returns exactly `count` points on the closed polyline `outline` (count >= 3), starting at
// outline[0] (or the first corner), in the same cyclic order.
Points ResampleOutline(const Points& outline, int count, const ResampleOptions& options = {});

// Indices of the corner vertices of `outline` (see ResampleOptions).
std::vector<int> FindCorners(const Points& outline, double corner_angle_degrees);

}  // namespace inbetween::solver
