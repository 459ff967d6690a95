// The inversion bound of the comesh line search (comesh_inner_loop.h): the largest step along a
// direction before any triangle of any shape reaches zero area. Internal to the comesh optimizer.
#pragma once

#include <vector>

#include "solver/core/types.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {

// Twice the area of a triangle at x + s dx, as c0 + c1 s + c2 s^2.
struct AreaPolynomial {
  double c0, c1, c2;
};

// The area polynomial of triangle t at positions x moving by dx.
inline AreaPolynomial AreaAlong(const Points& x, const Points& dx, const Triangle& t) {
  const Point e1 = x[t[1]] - x[t[0]], e2 = x[t[2]] - x[t[0]];
  const Point f1 = dx[t[1]] - dx[t[0]], f2 = dx[t[2]] - dx[t[0]];
  return {Cross(e1, e2), Cross(e1, f2) + Cross(f1, e2), Cross(f1, f2)};
}

// Largest step t such that every triangle of every shape keeps positive area on (0, t), for the
// displacements `disp` (ComeshLayout::Displacements): the smallest positive root of each
// triangle's area polynomial. A min over triangles, so the chunked parallel evaluation gives the
// same value for any thread count. A triangle that does not move adds nothing (its area
// polynomial is constant); +inf if none would invert.
double MaxNonInvertingStep(const std::vector<Triangle>& triangles,
                           const std::vector<Points>& shapes, const std::vector<Points>& disp,
                           int threads);

}  // namespace inbetween::solver
