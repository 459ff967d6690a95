// Test matrices for the sparse Cholesky tests.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <random>
#include <vector>

#include "solver/core/sparse_cholesky.h"

namespace inbetween::solver::testing {

// A dense n x n SPD matrix B B^T / n + I (B uniform in [-1, 1], from `seed`), upper triangle
// stored: one supernode of n columns in a supernodal factorization.
inline Eigen::SparseMatrix<double> DenseSpd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd b(n, n);
  for (Eigen::Index k = 0; k < b.size(); ++k) b.data()[k] = u(rng);
  const Eigen::MatrixXd a = b * b.transpose() / n + Eigen::MatrixXd::Identity(n, n);
  std::vector<Eigen::Triplet<double>> upper;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i <= j; ++i) upper.emplace_back(i, j, a(i, j));
  }
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(upper.begin(), upper.end());
  m.makeCompressed();
  return m;
}

// Factors `a` supernodally (it must be large enough to go supernodal) and simplicially and
// checks that the supernodal solution of two random right-hand sides is right and agrees with
// the simplicial one.
inline void ExpectSupernodalSolvesRight(const Eigen::SparseMatrix<double>& a) {
  SparseCholesky super(SparseCholesky::Method::kAuto), simplicial;
  ASSERT_TRUE(super.Compute(a).ok());
  ASSERT_TRUE(super.supernodal());
  ASSERT_TRUE(simplicial.Compute(a).ok());
  const Eigen::SparseMatrix<double> full = a.selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(a.rows(), 2);
  Eigen::MatrixXd x = b, y = b;
  ASSERT_TRUE(super.SolveInPlace(&x).ok());
  ASSERT_TRUE(simplicial.SolveInPlace(&y).ok());
  EXPECT_LT((full * x - b).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-10 * y.cwiseAbs().maxCoeff());
}

}  // namespace inbetween::solver::testing
