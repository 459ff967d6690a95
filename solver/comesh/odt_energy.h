// S-eq.1: ODT (Optimal Delaunay Triangulation) mesh energy of one shape, Chen & Xu 2004.
//
// The continuous ODT energy is the L1 error of the piecewise-linear interpolant of u(x) = |x|^2,
//   D(X) = (1/(d+1)) sum_v integral_{Omega_v} |x - x_v|^2 dx = integral (u_I - u) dx,   d = 2.
// On one triangle t with area |t| this integral is exactly
//   D_t = |t| * (|e_0|^2 + |e_1|^2 + |e_2|^2) / 12,
// so D = sum_t D_t, a translation-invariant sum we evaluate and differentiate per triangle.
// For an interior vertex j the terms of the integral of u over the (fixed) domain cancel and
//   dD/dX^j = (1/3) sum_{t in one-ring(j)} (d|t|/dX^j) sum_{p in t} |X^j - X^p|^2,
// which is S-eq.1 up to the positive per-vertex factor 3 / (8 Gamma_j) (Gamma_j = one-ring area):
// S-eq.1 is this gradient diagonally preconditioned (the classic ODT vertex update), not the
// gradient of a single energy, so we minimise D itself and leave preconditioning to the optimizer.
//
// Normalization (what the "mesh energy" column reports): D_hat = D / (A * h^2 / 4), with A the
// total area and h^2 = 4 A / (sqrt(3) T) the squared side of an equilateral triangle of the mean
// triangle area (T triangles). A tiling by equal equilateral triangles gives D_hat = 1 at any
// scale and resolution; a right-isosceles grid gives 2/sqrt(3) = 1.155. D_hat is dimensionless,
// invariant under similarity transforms and comparable across mesh sizes.
#pragma once

#include <array>
#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// D_t for the triangle (a, b, c). Returns +inf when its signed area is not positive. When
// `gradient` is given (and the value finite), stores dD_t/da, dD_t/db, dD_t/dc.
double OdtTriangleEnergy(const Point& a, const Point& b, const Point& c,
                         std::array<Point, 3>* gradient = nullptr);

// D(X) = sum_t D_t. +inf if any triangle is inverted or degenerate. When `gradient` is given it
// must have x.size() entries; dD/dX is ADDED to it (so several terms can share one buffer).
double OdtEnergy(const std::vector<Triangle>& triangles, const Points& x,
                 Points* gradient = nullptr);

// The normalizer A * h^2 / 4 = A^2 / (sqrt(3) T) of the comment above, for geometry x (uses the
// absolute triangle areas so it is defined for any input). Returns 0 for an empty mesh.
double OdtNormalization(const std::vector<Triangle>& triangles, const Points& x);

}  // namespace inbetween::solver
