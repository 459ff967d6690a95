// Sparse LU solve of a square, non-symmetric system A X = B (KLU, SuiteSparse), for systems
// Cholesky cannot take (the mean-value Tutte system of map_to_boundary.cpp). KLU is plain C with
// malloc: an allocation failure comes back as RESOURCE_EXHAUSTED, where Eigen's SparseLU is not
// exception-safe (its memory expansion frees a buffer, fails to allocate the new one and frees
// the dangling pointer again on retry: a double free, docs/hardening.md).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "absl/status/statusor.h"

namespace inbetween::solver {

// Solves A X = B for every column of B (A compressed, column-major, square, rows == B.rows()).
// Errors: INVALID_ARGUMENT (shape), FAILED_PRECONDITION (A singular), RESOURCE_EXHAUSTED (out of
// memory, or a size KLU's int indices cannot hold).
absl::StatusOr<Eigen::MatrixXd> SparseLuSolve(const Eigen::SparseMatrix<double>& a,
                                              const Eigen::MatrixXd& b);

}  // namespace inbetween::solver
