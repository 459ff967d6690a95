// KLU-backed sparse LU solve (see sparse_lu.h): BTF + AMD ordering, partial pivoting with a
// diagonal preference, no BLAS and no threads (deterministic, like sparse_cholesky.cpp).
#include "solver/core/sparse_lu.h"

#include <klu.h>

#include "absl/strings/str_cat.h"

namespace inbetween::solver {
namespace {

// Frees KLU's objects on every path (KLU never throws; this is about early returns).
struct KluState {
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
  KluState() { klu_defaults(&common); }
  ~KluState() {
    if (numeric != nullptr) klu_free_numeric(&numeric, &common);
    if (symbolic != nullptr) klu_free_symbolic(&symbolic, &common);
  }
  KluState(const KluState&) = delete;
  KluState& operator=(const KluState&) = delete;
};

absl::Status KluError(const KluState& k, absl::string_view step,
                      const Eigen::SparseMatrix<double>& a) {
  const std::string what = absl::StrCat("sparse LU: ", step, " of the ", a.rows(), " x ", a.cols(),
                                        " matrix (", a.nonZeros(), " nonzeros)");
  switch (k.common.status) {
    case KLU_OUT_OF_MEMORY:
      return absl::ResourceExhaustedError(absl::StrCat("out of memory in the ", what));
    case KLU_TOO_LARGE:
      return absl::ResourceExhaustedError(absl::StrCat("the ", what, " is too large"));
    case KLU_SINGULAR:
      return absl::FailedPreconditionError(absl::StrCat("the matrix is singular in the ", what));
    default:
      return absl::InternalError(absl::StrCat(what, " failed (KLU status ", k.common.status, ")"));
  }
}

}  // namespace

absl::StatusOr<Eigen::MatrixXd> SparseLuSolve(const Eigen::SparseMatrix<double>& a,
                                              const Eigen::MatrixXd& b) {
  if (a.rows() != a.cols() || a.rows() != b.rows()) {
    return absl::InvalidArgumentError(absl::StrCat("sparse LU: a ", a.rows(), " x ", a.cols(),
                                                   " matrix and ", b.rows(), " right-hand rows"));
  }
  if (!a.isCompressed()) return absl::InvalidArgumentError("sparse LU: matrix must be compressed");
  Eigen::MatrixXd x = b;  // a new object: a failed allocation leaves nothing half-built
  if (a.rows() == 0 || b.cols() == 0) return x;
  KluState k;
  // KLU reads the arrays only (its C prototypes are not const).
  int* ap = const_cast<int*>(a.outerIndexPtr());
  int* ai = const_cast<int*>(a.innerIndexPtr());
  double* ax = const_cast<double*>(a.valuePtr());
  const int n = static_cast<int>(a.rows());
  k.symbolic = klu_analyze(n, ap, ai, &k.common);
  if (k.symbolic == nullptr) return KluError(k, "ordering", a);
  k.numeric = klu_factor(ap, ai, ax, k.symbolic, &k.common);
  if (k.numeric == nullptr || k.common.status != KLU_OK) return KluError(k, "factorization", a);
  if (!klu_solve(k.symbolic, k.numeric, n, static_cast<int>(x.cols()), x.data(), &k.common)) {
    return KluError(k, "solve", a);
  }
  return x;
}

}  // namespace inbetween::solver
