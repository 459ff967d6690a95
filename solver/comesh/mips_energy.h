// S-eq.2: MIPS map energy between two shapes of a multimesh (and its closed-form gradient).
//
// Triangle k has edge matrices P = [X_i^1 - X_i^0, X_i^2 - X_i^0] in shape i and Q likewise in
// shape j; the map's deformation gradient is F = Q P^{-1} with singular values s1, s2, and
//   sigma*_k = s1/s2 + s2/s1 = ||F||_F ||F^{-1}||_F = ||F||_F^2 / det F          (S-eq.21)
//            = ||Q adj(P)||_F^2 / (det P det Q),
// using P^{-1} = adj(P) / det P. sigma* >= 2 with equality iff the map is conformal (a
// similarity), and sigma*(X_i, X_j) = sigma*(X_j, X_i) (S §3). The map energy weights it by the
// triangle's area in shape i, a_k(X_i) = det P / 2, as in S-eq.2:
//   C(X_i, X_j) = sum_k a_k(X_i) sigma*_k = sum_k ||Q adj(P)||_F^2 / (2 det Q).
// With M = Q adj(P), N = ||M||^2 and adj(P) = tr(P) I - P (2x2), the gradients are
//   dC_k/dQ = M adj(P)^T / det Q - N / (2 det Q^2) adj(Q)^T,
//   dC_k/dP = (tr(Q^T M) I - Q^T M) / det Q,
// and d/dX^1 = column 0, d/dX^2 = column 1, d/dX^0 = -(column 0 + column 1).
// Inverted or degenerate triangles (det P <= 0 or det Q <= 0) give +inf.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// The edge matrix [x1 - x0, x2 - x0] of a triangle with corners x (or triangle t of shape x).
Eigen::Matrix2d EdgeMatrix(const std::array<Point, 3>& x);
Eigen::Matrix2d EdgeMatrix(const Points& x, const Triangle& t);

// sigma* for edge matrices P (source) and Q (target); +inf unless both determinants are positive.
double MipsSigma(const Eigen::Matrix2d& p, const Eigen::Matrix2d& q);

// a(X_i) * sigma* for one triangle given its corners in shape i (xi) and shape j (xj). When the
// value is finite and a gradient pointer is given, stores d/dxi (resp. d/dxj) per corner.
double MipsTriangleEnergy(const std::array<Point, 3>& xi, const std::array<Point, 3>& xj,
                          std::array<Point, 3>* gradient_i = nullptr,
                          std::array<Point, 3>* gradient_j = nullptr);

// C(X_i, X_j) = sum_k a_k(X_i) sigma*_k(X_i, X_j). +inf if any triangle is inverted or degenerate
// in either shape. Gradients (each x.size() entries, either may be null) are ADDED to, so
// gradient_i == gradient_j (the same shape on both sides) accumulates correctly.
double MipsEnergy(const std::vector<Triangle>& triangles, const Points& xi, const Points& xj,
                  Points* gradient_i = nullptr, Points* gradient_j = nullptr);

// sigma*_k(X_i, X_j) for every triangle (+inf where inverted or degenerate).
std::vector<double> MipsSigmas(const std::vector<Triangle>& triangles, const Points& xi,
                               const Points& xj);

}  // namespace inbetween::solver
