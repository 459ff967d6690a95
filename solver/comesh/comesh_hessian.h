// Second derivatives of the comesh energies of one triangle (S-eq.1, S-eq.2), for the Newton-type
// preconditioner of the comesh optimizer (comesh_hessian_preconditioner.h).
//
// Both energies are translation invariant, so they are functions of a triangle's edge matrix
// E = [x1 - x0, x2 - x0] alone. Derivatives are taken with respect to u = vec(E) (column major:
// e1x, e1y, e2x, e2y); the corner Hessian is D^T H D with D = [[-I, I, 0], [-I, 0, I]] (4 x 6).
//
// ODT (odt_energy.h): D_t = A S / 12, A = det E / 2, S = |e1|^2 + |e2|^2 + |e2 - e1|^2, so
//   H = (grad A grad S^T + grad S grad A^T + A hess S + S hess A) / 12,
//   hess S = [[4 I, -2 I], [-2 I, 4 I]],  hess A = (1/2) J,  J = the 4 x 4 matrix of d(det E).
// MIPS (mips_energy.h): C_t = n / (2 d) with n = ||Q adj(P)||^2 and d = det Q.
//   In Q (P fixed), with G = adj(P) adj(P)^T: n = sum_ij G_ij q_i . q_j (q_i the columns of Q),
//     grad n = 2 (G (x) I) u,  hess n = 2 (G (x) I),
//     H_Q = hess n / (2d) - (grad n grad d^T + grad d grad n^T) / (2 d^2) + n grad d grad d^T / d^3
//           - n J / (2 d^2).
//   In P (Q fixed): adj(P) = [a1 a2] is linear in P, a = T u, so n = u^T T^T (K (+) K) T u with
//     K = Q^T Q and H_P = T^T (K (+) K) T / d, positive semidefinite.
// The mixed P-Q block is not computed: the preconditioner is block diagonal by shape.
#pragma once

#include <Eigen/Core>

namespace inbetween::solver {

using Matrix4 = Eigen::Matrix4d;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

// d^2 D_t / du^2 for the edge matrix e (any orientation; the formula is a polynomial).
Matrix4 OdtEdgeHessian(const Eigen::Matrix2d& e);

// d^2 C_t / du_P^2 (in *hp) and d^2 C_t / du_Q^2 (in *hq) for source edges p and target edges q;
// requires det q > 0. Either pointer may be null.
void MipsEdgeHessians(const Eigen::Matrix2d& p, const Eigen::Matrix2d& q, Matrix4* hp, Matrix4* hq);

// The nearest positive semidefinite matrix in the Frobenius norm (negative eigenvalues set to 0)
// of a symmetric 4 x 4 matrix, plus floor * (largest eigenvalue) on every eigenvalue so that the
// result is positive definite whenever the input has a positive eigenvalue. A clearly definite
// input (its Cholesky factor has no tiny pivot) skips the eigensolver and gets floor times an
// upper bound of its largest eigenvalue (the largest absolute row sum) instead.
Matrix4 ProjectPositiveDefinite(const Matrix4& h, double floor);

// D^T h D: the corner Hessian (corners 0, 1, 2; x and y interleaved) of an edge-space Hessian.
Matrix6 CornerHessian(const Matrix4& h);

}  // namespace inbetween::solver
