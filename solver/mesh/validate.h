// Validators for meshes and multimeshes, used by tests and by the server before it hands out a mesh.
#pragma once

#include <vector>

#include "absl/status/status.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

// Twice the signed area of triangle t in geometry x (positive = correctly oriented).
double SignedArea2(const Triangle& t, const Points& x);

// Number of triangles with signed area <= min_area2 / 2 (inverted or degenerate).
int CountInverted(const std::vector<Triangle>& triangles, const Points& x, double min_area2 = 0.0);

// Checks shared topology (indices in range, every shape has the same vertex count), no inverted
// or degenerate triangle in any shape. Errors name the shape and the triangle.
absl::Status ValidateMultimesh(const Multimesh& mesh);

}  // namespace inbetween::solver
