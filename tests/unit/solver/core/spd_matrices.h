// Test matrices for the sparse Cholesky tests.
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <random>
#include <vector>

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

}  // namespace inbetween::solver::testing
