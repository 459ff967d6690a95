// SparseCholesky: solves SPD systems, refactors on a fixed pattern, reports misuse.
#include "solver/core/sparse_cholesky.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iterator>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "tests/unit/solver/core/address_space.h"
#include "tests/unit/solver/core/spd_matrices.h"

namespace inbetween::solver {
namespace {

// A 2D grid Laplacian (5-point) plus `shift` on the diagonal: SPD for shift > 0.
// The graph Laplacian of an n x n grid, plus `shift` on the diagonal. reach 1: each node joined to
// its 4 axis neighbours (5-point stencil); reach r > 1: to every node of the (2r+1) x (2r+1)
// square around it, for a denser factor (CHOLMOD goes supernodal on a smaller grid).
Eigen::SparseMatrix<double> GridMatrix(int n, double shift, double scale = 1.0, int reach = 1) {
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
      if (reach == 1) {
        if (i + 1 < n) edge(id(i, j), id(i + 1, j));
        if (j + 1 < n) edge(id(i, j), id(i, j + 1));
        continue;
      }
      for (int dj = 0; dj <= reach; ++dj) {
        for (int di = -reach; di <= reach; ++di) {
          if ((dj == 0 && di <= 0) || i + di < 0 || i + di >= n || j + dj >= n) continue;
          edge(id(i, j), id(i + di, j + dj));
        }
      }
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

// The same for a supernodal factor, whose input tril(P A P^T) is built from the upper triangle
// once per analysis and refilled by each Factorize: values below the diagonal (here nonsense)
// are never read, and a refactorization reads the new values.
TEST(SparseCholeskyTest, SupernodalReadsOnlyTheUpperTriangleAndTheNewValues) {
  const Eigen::SparseMatrix<double> a = GridMatrix(100, 1e-2, 1.0, 3);
  Eigen::SparseMatrix<double> noisy = a;
  for (int j = 0; j < noisy.outerSize(); ++j) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(noisy, j); it; ++it) {
      if (it.row() > it.col()) it.valueRef() = -1e6;  // would make the matrix indefinite
    }
  }
  const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(a.rows(), 1);
  SparseCholesky chol(SparseCholesky::Method::kAuto);
  ASSERT_TRUE(chol.Compute(noisy).ok());
  ASSERT_TRUE(chol.supernodal());
  absl::StatusOr<Eigen::MatrixXd> x = chol.Solve(b);
  ASSERT_TRUE(x.ok());
  EXPECT_LT((a * *x - b).cwiseAbs().maxCoeff(), 1e-9);
  Eigen::SparseMatrix<double> scaled = noisy;
  for (int j = 0; j < scaled.outerSize(); ++j) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(scaled, j); it; ++it) {
      if (it.row() <= it.col()) it.valueRef() *= 4.0;
    }
  }
  ASSERT_TRUE(chol.Factorize(scaled).ok());
  x = chol.Solve(b);
  ASSERT_TRUE(x.ok());
  EXPECT_LT((4.0 * a * *x - b).cwiseAbs().maxCoeff(), 1e-9);
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

// Method::kAuto: CHOLMOD goes supernodal on a large grid (and stays simplicial on a small one);
// the supernodal solve agrees with the simplicial one, refactors on the analyzed pattern, and
// still reports a matrix that is not positive definite.
TEST(SparseCholeskyTest, AutoGoesSupernodalOnLargeMatricesWithTheSameSolution) {
  SparseCholesky small(SparseCholesky::Method::kAuto);
  ASSERT_TRUE(small.Compute(GridMatrix(6, 0.1)).ok());
  EXPECT_FALSE(small.supernodal());

  const Eigen::SparseMatrix<double> a = GridMatrix(100, 1e-3, 1.0, 3);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd b(a.rows(), 2);
  for (Eigen::Index k = 0; k < b.size(); ++k) b.data()[k] = u(rng);
  SparseCholesky super(SparseCholesky::Method::kAuto), simplicial;
  ASSERT_TRUE(super.Compute(a).ok());
  ASSERT_TRUE(super.supernodal());
  ASSERT_TRUE(simplicial.Compute(a).ok());
  EXPECT_FALSE(simplicial.supernodal());
  Eigen::MatrixXd x = b, y = b;
  ASSERT_TRUE(super.SolveInPlace(&x).ok());
  ASSERT_TRUE(simplicial.SolveInPlace(&y).ok());
  EXPECT_LT((a * x - b).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-9 * y.cwiseAbs().maxCoeff());
  // Any column count, and columns on several threads: the same numbers, bit for bit.
  Eigen::MatrixXd wide(a.rows(), 3);
  wide << b, b.col(0) - b.col(1);
  Eigen::MatrixXd serial = wide, parallel = wide, one = wide.col(2);
  ASSERT_TRUE(super.SolveInPlace(&serial).ok());
  ASSERT_TRUE(super.SolveInPlace(&parallel, 2).ok());
  ASSERT_TRUE(super.SolveInPlace(&one).ok());
  EXPECT_EQ(serial, parallel);
  EXPECT_EQ(serial.leftCols(2), x);
  EXPECT_EQ(serial.col(2), one);

  const Eigen::SparseMatrix<double> scaled = 3.0 * a;
  ASSERT_TRUE(super.Factorize(scaled).ok());
  x = b;
  ASSERT_TRUE(super.SolveInPlace(&x).ok());
  EXPECT_LT((scaled * x - b).cwiseAbs().maxCoeff(), 1e-9);

  SparseCholesky indefinite(SparseCholesky::Method::kAuto);
  EXPECT_EQ(indefinite.Compute(GridMatrix(100, -0.5, 1.0, 3)).code(),
            absl::StatusCode::kFailedPrecondition);
  EXPECT_FALSE(indefinite.factorized());
}

TEST(SparseCholeskyTest, SupernodalWhenAskedEvenOnSmallMatrices) {
  const Eigen::SparseMatrix<double> a = GridMatrix(6, 0.1);
  SparseCholesky super(SparseCholesky::Method::kSupernodal), simplicial;
  ASSERT_TRUE(super.Compute(a).ok());
  EXPECT_TRUE(super.supernodal());
  ASSERT_TRUE(simplicial.Compute(a).ok());
  const Eigen::MatrixXd b = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0);
  Eigen::MatrixXd x = b, y = b;
  ASSERT_TRUE(super.SolveInPlace(&x).ok());
  ASSERT_TRUE(simplicial.SolveInPlace(&y).ok());
  EXPECT_LT((a * x - b).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-12 * y.cwiseAbs().maxCoeff());
}

// A child forked from this process (which has factored nothing supernodally itself when the
// test runs alone) and capped at 16 MiB above its address space factors a 10k-unknown matrix
// supernodally or answers out of memory, in either case soon; it is killed after 60 s. With the
// BLAS set up at the first factorization instead of at load, it spun in OpenBLAS's
// blas_memory_alloc (process_overrides.cpp, kSetUpAtLoad).
TEST(SparseCholeskyTest, FirstSupernodalFactorizationUnderAMemoryCapDoesNotHang) {
  if (testing::kSanitizerBuild) GTEST_SKIP() << "RLIMIT_AS caps do not apply under ASan/TSan";
  const Eigen::SparseMatrix<double> a = GridMatrix(100, 0.1);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    rlimit cap;
    cap.rlim_cur = cap.rlim_max = testing::AddressSpaceBytes() + (size_t{16} << 20);
    if (setrlimit(RLIMIT_AS, &cap) != 0) _exit(3);
    SparseCholesky super(SparseCholesky::Method::kSupernodal);
    const absl::Status s = super.Compute(a);
    _exit(s.ok() && super.supernodal() ? 0 : absl::IsResourceExhausted(s) ? 1 : 2);
  }
  int status = 0;
  const auto start = std::chrono::steady_clock::now();
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() - start > std::chrono::seconds(60)) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      FAIL() << "the capped child still runs after 60 s";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_TRUE(WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 1) << WEXITSTATUS(status);
}

// Float substitutions: a supernodal factor's solves read its values rounded to float, so the
// solution is that of a slightly different matrix (close, not bit-equal); simplicial factors ignore
// the switch; a refactorization refreshes the float copy; it is deterministic.
TEST(SparseCholeskyTest, FloatSubstitutionsSolveCloselyOnSupernodalFactorsOnly) {
  const Eigen::SparseMatrix<double> a = GridMatrix(100, 1e-2, 1.0, 3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd b(a.rows(), 2);
  for (Eigen::Index k = 0; k < b.size(); ++k) b.data()[k] = u(rng);
  SparseCholesky exact(SparseCholesky::Method::kAuto), rounded(SparseCholesky::Method::kAuto);
  rounded.set_float_substitutions(true);
  ASSERT_TRUE(exact.Compute(a).ok());
  ASSERT_TRUE(rounded.Compute(a).ok());
  ASSERT_TRUE(rounded.supernodal());
  Eigen::MatrixXd x = b, y = b, y_again = b;
  ASSERT_TRUE(exact.SolveInPlace(&x).ok());
  ASSERT_TRUE(rounded.SolveInPlace(&y).ok());
  ASSERT_TRUE(rounded.SolveInPlace(&y_again, 2).ok());
  EXPECT_EQ(y, y_again);
  const double scale = x.cwiseAbs().maxCoeff();
  EXPECT_GT((x - y).cwiseAbs().maxCoeff(), 1e-12 * scale);  // it did read floats
  EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-4 * scale);
  EXPECT_LT((a * y - b).norm(), 1e-4 * b.norm());

  // New values on the same pattern: the float copy follows.
  const Eigen::SparseMatrix<double> scaled = 4.0 * a;
  ASSERT_TRUE(rounded.Factorize(scaled).ok());
  y = b;
  ASSERT_TRUE(rounded.SolveInPlace(&y).ok());
  EXPECT_LT((y - 0.25 * x).cwiseAbs().maxCoeff(), 1e-4 * 0.25 * scale);

  // A cancelled factorization leaves nothing to solve with; without the token it works again.
  CancelToken cancelled;
  cancelled.Cancel();
  EXPECT_EQ(rounded.Factorize(a, &cancelled).code(), absl::StatusCode::kCancelled);
  EXPECT_FALSE(rounded.factorized());
  ASSERT_TRUE(rounded.Factorize(a).ok());
  y = b;
  ASSERT_TRUE(rounded.SolveInPlace(&y).ok());
  EXPECT_EQ(y, y_again);

  // A simplicial factor ignores the switch: the same bits as without it.
  const Eigen::SparseMatrix<double> small = GridMatrix(20, 0.1);
  SparseCholesky plain, switched;
  switched.set_float_substitutions(true);
  ASSERT_TRUE(plain.Compute(small).ok());
  ASSERT_TRUE(switched.Compute(small).ok());
  ASSERT_FALSE(switched.supernodal());
  Eigen::MatrixXd p = Eigen::MatrixXd::Ones(small.rows(), 1), q = p;
  ASSERT_TRUE(plain.SolveInPlace(&p).ok());
  ASSERT_TRUE(switched.SolveInPlace(&q).ok());
  EXPECT_EQ(p, q);
}

// CHOLMOD's OpenMP regions run on the calling thread (the GOMP_parallel definition in
// process_overrides.cpp, which the test binaries link): a supernodal factorization starts no
// thread. Without that definition libgomp starts a pool of 3 workers at the first region with its
// team of 4 (they stay alive). ctest runs every test in its own process, so no earlier test has
// started them.
int ThreadCount() {
  return static_cast<int>(std::distance(std::filesystem::directory_iterator("/proc/self/task"),
                                        std::filesystem::directory_iterator()));
}

TEST(SparseCholeskyTest, SupernodalFactorizationStartsNoThread) {
  const Eigen::SparseMatrix<double> a = GridMatrix(100, 1e-3, 1.0, 3);
  const int before = ThreadCount();
  SparseCholesky super(SparseCholesky::Method::kAuto);
  ASSERT_TRUE(super.Compute(a).ok());
  ASSERT_TRUE(super.supernodal());
  ASSERT_TRUE(super.Factorize(2.0 * a).ok());
  EXPECT_EQ(ThreadCount(), before);
}

// With a cancellation token the simplicial factor is computed in row blocks (several here): the
// same factor, bit for bit, on a first factorization and on a refactorization with new values.
TEST(SparseCholeskyTest, CancellableSimplicialFactorizationIsBitIdentical) {
  const Eigen::SparseMatrix<double> a = GridMatrix(100, 0.1);
  const Eigen::SparseMatrix<double> a2 = GridMatrix(100, 0.3, 2.0);  // same pattern
  ASSERT_GT(a.rows(), 3 * SparseCholesky::kCancelRows);
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(a.rows(), 1);
  CancelToken token;
  SparseCholesky plain, blocks;
  ASSERT_TRUE(plain.Analyze(a).ok());
  ASSERT_TRUE(blocks.Analyze(a).ok());
  for (const auto* m : {&a, &a2}) {
    ASSERT_TRUE(plain.Factorize(*m).ok());
    const absl::Status st = blocks.Factorize(*m, &token);
    ASSERT_TRUE(st.ok()) << st << (m == &a ? " first" : " refactor");
    ASSERT_FALSE(blocks.supernodal());
    Eigen::MatrixXd x = b, y = b;
    ASSERT_TRUE(plain.SolveInPlace(&x).ok());
    ASSERT_TRUE(blocks.SolveInPlace(&y).ok());
    EXPECT_EQ(x, y);
    EXPECT_LT((*m * y - b).cwiseAbs().maxCoeff(), 1e-9);
  }
}

// A set token stops a factorization at its first poll, simplicial (between row blocks) and
// supernodal (at a supernode: LAPACK's dpotrf_ as CHOLMOD calls it is ours, see the .cpp): the
// answer is CANCELLED, not "not positive definite", the object is not factorized, and a
// factorization without the token afterwards is correct. Other objects are unaffected.
TEST(SparseCholeskyTest, CancelledFactorizationAnswersCancelledAndCanBeRedone) {
  const Eigen::SparseMatrix<double> small = GridMatrix(60, 0.1);
  const Eigen::SparseMatrix<double> large = GridMatrix(100, 1e-3, 1.0, 3);
  CancelToken cancelled;
  cancelled.Cancel();
  for (const auto* m : {&small, &large}) {
    SparseCholesky chol(SparseCholesky::Method::kAuto);
    ASSERT_TRUE(chol.Analyze(*m).ok());
    EXPECT_EQ(chol.supernodal(), m == &large);
    const absl::Status status = chol.Factorize(*m, &cancelled);
    EXPECT_EQ(status.code(), absl::StatusCode::kCancelled) << status;
    EXPECT_FALSE(chol.factorized());
    EXPECT_EQ(chol.Solve(Eigen::MatrixXd::Ones(m->rows(), 1)).status().code(),
              absl::StatusCode::kFailedPrecondition);
    // The same object, and another one, factor correctly without the token.
    SparseCholesky other(SparseCholesky::Method::kAuto);
    for (SparseCholesky* c : {&chol, &other}) {
      ASSERT_TRUE(c == &chol ? c->Factorize(*m).ok() : c->Compute(*m).ok());
      const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(m->rows(), 1);
      absl::StatusOr<Eigen::MatrixXd> x = c->Solve(b);
      ASSERT_TRUE(x.ok());
      EXPECT_LT((*m * *x - b).cwiseAbs().maxCoeff(), 1e-8);
    }
  }
  // An indefinite matrix without a cancelled token is still "not positive definite".
  SparseCholesky indefinite(SparseCholesky::Method::kAuto);
  ASSERT_TRUE(indefinite.Analyze(GridMatrix(100, -0.5, 1.0, 3)).ok());
  CancelToken live;
  EXPECT_EQ(indefinite.Factorize(GridMatrix(100, -0.5, 1.0, 3), &live).code(),
            absl::StatusCode::kFailedPrecondition);
}

// A set token stops the substitutions (simplicial and supernodal, one column or several on two
// threads) with CANCELLED; the factor is untouched, so the next solve is right, and a token that
// is never set changes no bit of the result.
TEST(SparseCholeskyTest, CancelledSolveAnswersCancelledAndTheFactorStaysUsable) {
  for (const bool large : {false, true}) {
    SCOPED_TRACE(large ? "supernodal" : "simplicial");
    const Eigen::SparseMatrix<double> a =
        large ? GridMatrix(100, 1e-3, 1.0, 3) : GridMatrix(30, 0.1);
    SparseCholesky chol(SparseCholesky::Method::kAuto);
    ASSERT_TRUE(chol.Compute(a).ok());
    ASSERT_EQ(chol.supernodal(), large);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Eigen::MatrixXd b(a.rows(), 2);
    for (Eigen::Index k = 0; k < b.size(); ++k) b.data()[k] = u(rng);
    Eigen::MatrixXd reference = b;
    ASSERT_TRUE(chol.SolveInPlace(&reference).ok());

    CancelToken unset;
    Eigen::MatrixXd x = b;
    ASSERT_TRUE(chol.SolveInPlace(&x, 2, &unset).ok());
    EXPECT_EQ(x, reference);

    CancelToken cancel;
    cancel.Cancel();
    for (const int threads : {1, 2}) {
      Eigen::MatrixXd two = b, one = b.col(0);
      EXPECT_EQ(chol.SolveInPlace(&two, threads, &cancel).code(), absl::StatusCode::kCancelled);
      EXPECT_EQ(chol.SolveInPlace(&one, threads, &cancel).code(), absl::StatusCode::kCancelled);
    }
    x = b;
    ASSERT_TRUE(chol.SolveInPlace(&x).ok());
    EXPECT_EQ(x, reference);
    EXPECT_LT((a * x - b).cwiseAbs().maxCoeff(), 1e-9);
  }
}

// A caller's ordering (here AMD of a coarser graph expanded, as the comesh Hessian does, and the
// reverse order) gives a correct factor; a non-permutation is refused.
TEST(SparseCholeskyTest, AnalyzesWithAGivenOrdering) {
  const Eigen::SparseMatrix<double> a = GridMatrix(30, 0.1);
  const int n = static_cast<int>(a.rows());
  std::vector<int> outer(a.outerIndexPtr(), a.outerIndexPtr() + n + 1);
  std::vector<int> inner(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  absl::StatusOr<std::vector<int>> amd = SparseCholesky::AmdOrdering(outer, inner);
  ASSERT_TRUE(amd.ok()) << amd.status();
  std::vector<int> sorted = *amd;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < n; ++k) ASSERT_EQ(sorted[k], k);
  std::vector<int> reverse(n);
  for (int k = 0; k < n; ++k) reverse[k] = n - 1 - k;
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(n, 1);
  for (const std::vector<int>* ordering : {&*amd, &reverse}) {
    SparseCholesky chol;
    ASSERT_TRUE(chol.Analyze(a, ordering).ok());
    ASSERT_TRUE(chol.Factorize(a).ok());
    absl::StatusOr<Eigen::MatrixXd> x = chol.Solve(b);
    ASSERT_TRUE(x.ok());
    EXPECT_LT((a * *x - b).cwiseAbs().maxCoeff(), 1e-9);
  }
  std::vector<int> repeated = reverse;
  repeated[0] = repeated[1];
  SparseCholesky chol;
  EXPECT_EQ(chol.Analyze(a, &repeated).code(), absl::StatusCode::kInvalidArgument);
  std::vector<int> short_one(reverse.begin(), reverse.end() - 1);
  EXPECT_EQ(chol.Analyze(a, &short_one).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(SparseCholesky::AmdOrdering({0, 2}, {0, 1}).status().code(),
            absl::StatusCode::kInvalidArgument);  // row 1 of a 1 x 1 pattern
}

using testing::DenseSpd;

// A dense block of SparseCholesky::kDensePanel * 2 columns or more (one supernode here) is
// factored in panels by the overrides' dpotrf_/dsyrk_ (process_overrides.cpp): the solution is
// right, and a pivot that fails in a later panel is reported at its own column, as LAPACK would.
TEST(SparseCholeskyTest, LargeDenseSupernodesAreFactoredInPanels) {
  const int n = 5 * SparseCholesky::kDensePanel + 37;
  Eigen::SparseMatrix<double> a = DenseSpd(n, 5);
  testing::ExpectSupernodalSolvesRight(a);

  // In the identity order, a hugely negative diagonal entry at column 3 * kDensePanel + 5 is the
  // first pivot that fails (the leading block before it is SPD).
  const int bad = 3 * SparseCholesky::kDensePanel + 5;
  a.coeffRef(bad, bad) = -1e3;
  std::vector<int> identity(n);
  for (int k = 0; k < n; ++k) identity[k] = k;
  SparseCholesky indefinite(SparseCholesky::Method::kAuto);
  ASSERT_TRUE(indefinite.Analyze(a, &identity).ok());
  ASSERT_TRUE(indefinite.supernodal());
  const absl::Status status = indefinite.Factorize(a);
  EXPECT_EQ(status.code(), absl::StatusCode::kFailedPrecondition) << status;
  EXPECT_NE(status.message().find(absl::StrCat("pivot ", bad, " of ", n)), std::string::npos)
      << status;
}

// process_overrides.cpp defines dgemm_ (for CHOLMOD), skipping the work while a cancelled
// factorization winds down on the calling thread.
extern "C" void dgemm_(const char* transa, const char* transb, const int* m, const int* n,
                       const int* k, const double* alpha, const double* a, const int* lda,
                       const double* b, const int* ldb, const double* beta, double* c,
                       const int* ldc, size_t transa_length, size_t transb_length);

// A cancel may land anywhere in a panelled factorization (between panels, or in a BLAS call the
// hooks then skip), and in the first one after an analysis also while the factor's values are
// allocated and their pages touched: the answer is OK with a right factor or CANCELLED, never
// "not positive definite", BLAS calls on the thread compute again afterwards, and a
// factorization without the token is right.
void CancelAtSpreadMoments(bool fresh_analysis) {
  const int n = 8 * SparseCholesky::kDensePanel;
  const Eigen::SparseMatrix<double> a = DenseSpd(n, 7);
  const Eigen::SparseMatrix<double> full = a.selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(n, 1);
  SparseCholesky chol(SparseCholesky::Method::kAuto);
  ASSERT_TRUE(chol.Analyze(a).ok());
  ASSERT_TRUE(chol.supernodal());
  // Cancels spread from before the start to after the end of an uncancelled factorization.
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(chol.Factorize(a).ok());
  const std::chrono::duration<double> whole = std::chrono::steady_clock::now() - start;
  int cancelled = 0;
  const Eigen::SparseMatrix<double> small = DenseSpd(SparseCholesky::kDensePanel, 3);
  for (int trial = 0; trial < 12; ++trial) {
    if (fresh_analysis) {
      // A smaller factor first, so that `a`'s values need a new array (see the .cpp).
      ASSERT_TRUE(chol.Analyze(small).ok());
      ASSERT_TRUE(chol.Factorize(small).ok());
      ASSERT_TRUE(chol.Analyze(a).ok());
    }
    CancelToken token;
    std::thread canceller([&token, trial, whole] {
      std::this_thread::sleep_for(whole * trial / 10);
      token.Cancel();
    });
    const absl::Status status = chol.Factorize(a, &token);
    canceller.join();
    ASSERT_TRUE(status.ok() || absl::IsCancelled(status)) << "trial " << trial << ": " << status;
    // BLAS on this thread computes again afterwards (the hooks' skipping ends with the call).
    const Eigen::MatrixXd lhs = Eigen::MatrixXd::Random(3, 4), rhs = Eigen::MatrixXd::Random(4, 2);
    Eigen::MatrixXd product = Eigen::MatrixXd::Zero(3, 2);
    const int rows = 3, cols = 2, inner = 4;
    const double one = 1.0, zero = 0.0;
    dgemm_("N", "N", &rows, &cols, &inner, &one, lhs.data(), &rows, rhs.data(), &inner, &zero,
           product.data(), &rows, 1, 1);
    EXPECT_LT((product - lhs * rhs).cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
    if (!status.ok()) {
      ++cancelled;
      EXPECT_FALSE(chol.factorized());
      ASSERT_TRUE(chol.Factorize(a).ok()) << "trial " << trial;
    }
    Eigen::MatrixXd x = b;
    ASSERT_TRUE(chol.SolveInPlace(&x).ok());
    EXPECT_LT((full * x - b).cwiseAbs().maxCoeff(), 1e-10) << "trial " << trial;
  }
  ::testing::Test::RecordProperty("cancelled", cancelled);
}

TEST(SparseCholeskyTest, CancelAtAnyMomentOfAPanelledFactorizationIsClean) {
  CancelAtSpreadMoments(/*fresh_analysis=*/false);
}

TEST(SparseCholeskyTest, CancelAtAnyMomentOfTheFirstFactorizationAfterAnAnalysisIsClean) {
  CancelAtSpreadMoments(/*fresh_analysis=*/true);
}

// One object analyzes and factors supernodal matrices of changing size and pattern in turn (a
// new factor reuses the previous one's value array when it is large enough): every solution is
// right, with and without a cancellation token.
TEST(SparseCholeskyTest, ReanalysesOfOtherPatternsFactorCorrectly) {
  SparseCholesky chol(SparseCholesky::Method::kAuto);
  const CancelToken live;
  int step = 0;
  for (int n : {90, 100, 70, 100, 60, 95}) {
    const Eigen::SparseMatrix<double> a = GridMatrix(n, 1e-2 * n, 1.0, 3);
    ASSERT_TRUE(chol.Analyze(a).ok());
    ASSERT_TRUE(chol.supernodal()) << n;
    ASSERT_TRUE(chol.Factorize(a, step++ % 2 == 0 ? &live : nullptr).ok()) << n;
    const Eigen::SparseMatrix<double> full = a.selfadjointView<Eigen::Upper>();
    const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(a.rows(), 1);
    Eigen::MatrixXd x = b;
    ASSERT_TRUE(chol.SolveInPlace(&x).ok());
    EXPECT_LT((full * x - b).cwiseAbs().maxCoeff(), 1e-8) << n;
  }
}

// Supernodal factorizations on several threads at once (the comesh preconditioner factors its
// shapes in parallel) are all correct, whatever BLAS the system provides.
TEST(SparseCholeskyTest, ConcurrentSupernodalFactorizationsAreCorrect) {
  const Eigen::SparseMatrix<double> a = GridMatrix(90, 1e-2, 1.0, 3);
  const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(a.rows(), 1);
  std::vector<double> residual(4, 0.0);
  std::vector<int> ok(4, 0);
  std::vector<std::thread> threads;
  for (int w = 0; w < 4; ++w) {
    threads.emplace_back([&, w] {
      const Eigen::SparseMatrix<double> m = (1.0 + w) * a;
      SparseCholesky chol(SparseCholesky::Method::kAuto);
      for (int round = 0; round < 6; ++round) {
        if (!chol.Compute(m).ok() || !chol.supernodal()) return;
        Eigen::MatrixXd x = b;
        if (!chol.SolveInPlace(&x).ok()) return;
        residual[w] = std::max(residual[w], (m * x - b).cwiseAbs().maxCoeff());
      }
      ok[w] = 1;
    });
  }
  for (std::thread& t : threads) t.join();
  for (int w = 0; w < 4; ++w) {
    EXPECT_EQ(ok[w], 1) << "thread " << w;
    EXPECT_LT(residual[w], 1e-9) << "thread " << w;
  }
}

}  // namespace
}  // namespace inbetween::solver
