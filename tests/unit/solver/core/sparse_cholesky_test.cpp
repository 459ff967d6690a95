// SparseCholesky: solves SPD systems, refactors on a fixed pattern, reports misuse.
#include "solver/core/sparse_cholesky.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace inbetween::solver {
namespace {

// A 2D grid Laplacian (5-point) plus `shift` on the diagonal: SPD for shift > 0.
Eigen::SparseMatrix<double> GridMatrix(int n, double shift, double scale = 1.0) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j) { return j * n + i; };
  auto edge = [&](int a, int b) {
    t.emplace_back(a, b, -scale);
    t.emplace_back(b, a, -scale);
    t.emplace_back(a, a, scale);
    t.emplace_back(b, b, scale);
  };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      t.emplace_back(id(i, j), id(i, j), shift);
      if (i + 1 < n) edge(id(i, j), id(i + 1, j));
      if (j + 1 < n) edge(id(i, j), id(i, j + 1));
    }
  }
  Eigen::SparseMatrix<double> m(n * n, n * n);
  m.setFromTriplets(t.begin(), t.end());
  m.makeCompressed();
  return m;
}

TEST(SparseCholeskyTest, SolvesSpdSystemWithSeveralColumns) {
  const Eigen::SparseMatrix<double> a = GridMatrix(12, 0.01);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd x_true(a.rows(), 3);
  for (Eigen::Index k = 0; k < x_true.size(); ++k) x_true.data()[k] = u(rng);
  const Eigen::MatrixXd b = a * x_true;

  SparseCholesky chol;
  ASSERT_TRUE(chol.Compute(a).ok());
  absl::StatusOr<Eigen::MatrixXd> x = chol.Solve(b);
  ASSERT_TRUE(x.ok()) << x.status();
  EXPECT_LT((*x - x_true).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((a * *x - b).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(SparseCholeskyTest, SolveInPlaceMatchesForAnyColumnCountAndReusesItsScratch) {
  const Eigen::SparseMatrix<double> a = GridMatrix(15, 0.05);
  SparseCholesky chol;
  ASSERT_TRUE(chol.Compute(a).ok());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int columns : {1, 2, 3, 5, 2, 1}) {  // scratch grows and shrinks
    Eigen::MatrixXd x_true(a.rows(), columns);
    for (Eigen::Index k = 0; k < x_true.size(); ++k) x_true.data()[k] = u(rng);
    Eigen::MatrixXd b = a * x_true;
    const Eigen::MatrixXd b0 = b;
    ASSERT_TRUE(chol.SolveInPlace(&b).ok());
    EXPECT_LT((b - x_true).cwiseAbs().maxCoeff(), 1e-11) << columns;
    // Each column is solved exactly as on its own (columns do not mix).
    for (int q = 0; q < columns; ++q) {
      Eigen::MatrixXd single = b0.col(q);
      ASSERT_TRUE(chol.SolveInPlace(&single).ok());
      EXPECT_EQ(single.col(0), b.col(q));
    }
  }
  Eigen::MatrixXd wrong(a.rows() + 1, 2);
  EXPECT_EQ(chol.SolveInPlace(&wrong).code(), absl::StatusCode::kInvalidArgument);
  Eigen::MatrixXd empty(a.rows(), 0);
  EXPECT_TRUE(chol.SolveInPlace(&empty).ok());
  SparseCholesky unfactored;
  Eigen::MatrixXd b(4, 1);
  EXPECT_EQ(unfactored.SolveInPlace(&b).code(), absl::StatusCode::kFailedPrecondition);
}

TEST(SparseCholeskyTest, RefactorsNewValuesOnTheAnalyzedPattern) {
  const Eigen::SparseMatrix<double> a = GridMatrix(8, 1.0);
  const Eigen::SparseMatrix<double> a2 = GridMatrix(8, 3.0, 2.0);  // same pattern
  SparseCholesky chol;
  ASSERT_TRUE(chol.Analyze(a).ok());
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0);
  for (const auto* m : {&a, &a2, &a}) {
    ASSERT_TRUE(chol.Factorize(*m).ok());
    absl::StatusOr<Eigen::MatrixXd> x = chol.Solve(b);
    ASSERT_TRUE(x.ok());
    EXPECT_LT((*m * *x - b).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(SparseCholeskyTest, ReadsOnlyTheUpperTriangle) {
  const Eigen::SparseMatrix<double> a = GridMatrix(5, 0.5);
  Eigen::SparseMatrix<double> upper = a.triangularView<Eigen::Upper>();
  upper.makeCompressed();
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(a.rows());
  SparseCholesky chol;
  ASSERT_TRUE(chol.Compute(upper).ok());
  absl::StatusOr<Eigen::MatrixXd> x = chol.Solve(b);
  ASSERT_TRUE(x.ok());
  EXPECT_LT((a * *x - b).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(SparseCholeskyTest, ReportsMisuse) {
  SparseCholesky chol;
  EXPECT_EQ(chol.Solve(Eigen::MatrixXd::Ones(4, 1)).status().code(),
            absl::StatusCode::kFailedPrecondition);
  const Eigen::SparseMatrix<double> a = GridMatrix(4, 1.0);
  EXPECT_EQ(chol.Factorize(a).code(), absl::StatusCode::kFailedPrecondition);  // no Analyze
  ASSERT_TRUE(chol.Compute(a).ok());
  EXPECT_EQ(chol.Solve(Eigen::MatrixXd::Ones(3, 1)).status().code(),
            absl::StatusCode::kInvalidArgument);
  // A different pattern.
  Eigen::SparseMatrix<double> d(16, 16);
  d.setIdentity();
  d.makeCompressed();
  EXPECT_EQ(chol.Factorize(d).code(), absl::StatusCode::kInvalidArgument);
  // Not positive definite: the singular pure Laplacian with a negative shift.
  EXPECT_EQ(chol.Compute(GridMatrix(4, -0.5)).code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_FALSE(chol.factorized());
  Eigen::SparseMatrix<double> rect(3, 4);
  EXPECT_EQ(chol.Analyze(rect).code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace inbetween::solver
