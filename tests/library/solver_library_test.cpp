// The solver library as another program links it: without inbetween_process_overrides (no BLAS,
// LAPACK or libgomp entry points of ours, OpenBLAS and SuiteSparse's allocator left as the
// program set them). Factorizations are still right and cancellable; CHOLMOD's calls go to the
// system's LAPACK and libgomp.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "solver/core/cancel.h"
#include "solver/core/sparse_cholesky.h"
#include "tests/unit/solver/core/spd_matrices.h"

namespace inbetween::solver {
namespace {

// The file that defines `symbol` in this process, as the dynamic linker resolves it.
std::string DefiningFile(const char* symbol) {
  void* address = dlsym(RTLD_DEFAULT, symbol);
  Dl_info info{};
  if (address == nullptr || dladdr(address, &info) == 0 || info.dli_fname == nullptr) return "";
  return info.dli_fname;
}

std::string ThisProgram() {
  std::vector<char> path(4096, '\0');
  const ssize_t n = readlink("/proc/self/exe", path.data(), path.size() - 1);
  return n > 0 ? std::string(path.data(), static_cast<size_t>(n)) : "";
}

using testing::DenseSpd;

TEST(SolverLibraryTest, LinksNoneOfTheProcessWideOverrides) {
  const std::string program = ThisProgram();
  ASSERT_FALSE(program.empty());
  for (const char* symbol : {"dpotrf_", "dsyrk_", "dgemm_", "dtrsm_", "GOMP_parallel"}) {
    const std::string file = DefiningFile(symbol);
    EXPECT_FALSE(file.empty()) << symbol << " is not defined in this process";
    EXPECT_NE(file, program) << symbol << " is defined by the test program itself";
  }
}

TEST(SolverLibraryTest, SupernodalFactorizationIsRightWithTheSystemLapack) {
  const int n = 5 * SparseCholesky::kDensePanel + 37;
  const Eigen::SparseMatrix<double> a = DenseSpd(n, 5);
  testing::ExpectSupernodalSolvesRight(a);
}

// Without the overrides' cancel points a started supernodal factorization runs to its end, but a
// token set before it is still answered (the value array's allocation and the scatter poll), and
// the factor is right afterwards.
TEST(SolverLibraryTest, CancelledSupernodalFactorizationAnswersCancelledAndCanBeRedone) {
  const int n = 3 * SparseCholesky::kDensePanel;
  const Eigen::SparseMatrix<double> a = DenseSpd(n, 7);
  SparseCholesky chol(SparseCholesky::Method::kAuto);
  ASSERT_TRUE(chol.Analyze(a).ok());
  ASSERT_TRUE(chol.supernodal());
  CancelToken token;
  token.Cancel();
  EXPECT_EQ(chol.Factorize(a, &token).code(), absl::StatusCode::kCancelled);
  ASSERT_TRUE(chol.Factorize(a).ok());
  EXPECT_EQ(chol.Factorize(2.0 * a, &token).code(), absl::StatusCode::kCancelled);
  ASSERT_TRUE(chol.Factorize(2.0 * a).ok());
  const Eigen::SparseMatrix<double> full = 2.0 * Eigen::SparseMatrix<double>(
                                                     a.selfadjointView<Eigen::Upper>());
  const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(n, 1);
  Eigen::MatrixXd x = b;
  ASSERT_TRUE(chol.SolveInPlace(&x).ok());
  EXPECT_LT((full * x - b).cwiseAbs().maxCoeff(), 1e-10);
}

}  // namespace
}  // namespace inbetween::solver
