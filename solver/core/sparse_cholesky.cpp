// CHOLMOD-backed sparse LDL^T (see sparse_cholesky.h). Simplicial factorization with an AMD
// ordering: no BLAS and no threads, so results are bit-identical run to run; for the planar
// meshes we solve (10^2..10^5 vertices) simplicial is as fast as supernodal.
#include "solver/core/sparse_cholesky.h"

#include <cholmod.h>

#include <algorithm>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"

namespace inbetween::solver {

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_factor* factor = nullptr;
  bool factorized = false;
  int n = 0;
  // The analyzed pattern, to check that Factorize gets the same structure.
  std::vector<int> outer;
  std::vector<int> inner;

  Impl() {
    cholmod_start(&common);
    common.print = 0;  // errors come back as absl::Status, not on stderr
    common.supernodal = CHOLMOD_SIMPLICIAL;
    common.final_ll = false;
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_AMD;
    common.postorder = true;
  }
  ~Impl() {
    if (factor != nullptr) cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

namespace {

// A non-owning CHOLMOD view of a compressed column-major Eigen matrix, read as symmetric upper.
cholmod_sparse View(const Eigen::SparseMatrix<double>& a) {
  cholmod_sparse s{};
  s.nrow = static_cast<size_t>(a.rows());
  s.ncol = static_cast<size_t>(a.cols());
  s.nzmax = static_cast<size_t>(a.nonZeros());
  s.p = const_cast<int*>(a.outerIndexPtr());
  s.i = const_cast<int*>(a.innerIndexPtr());
  s.nz = nullptr;
  s.x = const_cast<double*>(a.valuePtr());
  s.z = nullptr;
  s.stype = 1;
  s.itype = CHOLMOD_INT;
  s.xtype = CHOLMOD_REAL;
  s.dtype = CHOLMOD_DOUBLE;
  s.sorted = 1;
  s.packed = 1;
  return s;
}

absl::Status CheckShape(const Eigen::SparseMatrix<double>& a) {
  if (a.rows() != a.cols()) {
    return absl::InvalidArgumentError(
        absl::StrCat("SparseCholesky: matrix must be square, got ", a.rows(), "x", a.cols()));
  }
  if (!a.isCompressed()) {
    return absl::InvalidArgumentError("SparseCholesky: matrix must be compressed");
  }
  return absl::OkStatus();
}

}  // namespace

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;
SparseCholesky::~SparseCholesky() = default;

absl::Status SparseCholesky::Analyze(const Eigen::SparseMatrix<double>& a) {
  if (absl::Status s = CheckShape(a); !s.ok()) return s;
  Impl& m = *impl_;
  if (m.factor != nullptr) cholmod_free_factor(&m.factor, &m.common);
  m.factorized = false;
  m.n = static_cast<int>(a.rows());
  m.outer.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.cols() + 1);
  m.inner.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  cholmod_sparse view = View(a);
  m.factor = cholmod_analyze(&view, &m.common);
  if (m.factor == nullptr || m.common.status < CHOLMOD_OK) {
    return absl::InternalError(absl::StrCat(
        "SparseCholesky: symbolic analysis failed (CHOLMOD status ", m.common.status, ")"));
  }
  return absl::OkStatus();
}

absl::Status SparseCholesky::Factorize(const Eigen::SparseMatrix<double>& a) {
  if (absl::Status s = CheckShape(a); !s.ok()) return s;
  Impl& m = *impl_;
  if (m.factor == nullptr) {
    return absl::FailedPreconditionError("SparseCholesky: Factorize before Analyze");
  }
  const bool same_pattern = a.rows() == m.n &&
                            std::equal(m.outer.begin(), m.outer.end(), a.outerIndexPtr()) &&
                            static_cast<size_t>(a.nonZeros()) == m.inner.size() &&
                            std::equal(m.inner.begin(), m.inner.end(), a.innerIndexPtr());
  if (!same_pattern) {
    return absl::InvalidArgumentError(
        "SparseCholesky: Factorize needs the pattern that was analyzed");
  }
  m.factorized = false;
  cholmod_sparse view = View(a);
  const int ok = cholmod_factorize(&view, m.factor, &m.common);
  if (!ok || m.common.status < CHOLMOD_OK) {
    return absl::InternalError(absl::StrCat(
        "SparseCholesky: numeric factorization failed (CHOLMOD status ", m.common.status, ")"));
  }
  if (m.common.status == CHOLMOD_NOT_POSDEF || m.factor->minor < m.factor->n) {
    return absl::FailedPreconditionError(
        absl::StrCat("SparseCholesky: matrix is not positive definite (pivot ", m.factor->minor,
                     " of ", m.factor->n, ")"));
  }
  // Simplicial LDL^T only stops at zero pivots; a negative one means "not positive definite"
  // too, which is what callers rely on (an SPD energy Hessian, not a saddle point).
  if (!m.factor->is_ll && !m.factor->is_super) {
    const int* p = static_cast<const int*>(m.factor->p);
    const double* x = static_cast<const double*>(m.factor->x);
    for (size_t j = 0; j < m.factor->n; ++j) {
      if (!(x[p[j]] > 0.0)) {
        return absl::FailedPreconditionError(
            absl::StrCat("SparseCholesky: matrix is not positive definite (pivot ", j, " of ",
                         m.factor->n, " is ", x[p[j]], ")"));
      }
    }
  }
  m.factorized = true;
  return absl::OkStatus();
}

absl::Status SparseCholesky::Compute(const Eigen::SparseMatrix<double>& a) {
  if (absl::Status s = Analyze(a); !s.ok()) return s;
  return Factorize(a);
}

absl::StatusOr<Eigen::MatrixXd> SparseCholesky::Solve(const Eigen::MatrixXd& b) const {
  Impl& m = *impl_;
  if (!m.factorized) {
    return absl::FailedPreconditionError("SparseCholesky: Solve before a successful Factorize");
  }
  if (b.rows() != m.n) {
    return absl::InvalidArgumentError(
        absl::StrCat("SparseCholesky: right-hand side has ", b.rows(), " rows, matrix has ", m.n));
  }
  if (b.cols() == 0) return Eigen::MatrixXd(m.n, 0);
  Eigen::MatrixXd rhs = b;  // CHOLMOD takes a non-const pointer
  cholmod_dense view{};
  view.nrow = static_cast<size_t>(rhs.rows());
  view.ncol = static_cast<size_t>(rhs.cols());
  view.nzmax = static_cast<size_t>(rhs.size());
  view.d = static_cast<size_t>(rhs.rows());
  view.x = rhs.data();
  view.z = nullptr;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, m.factor, &view, &m.common);
  if (x == nullptr) {
    return absl::InternalError(
        absl::StrCat("SparseCholesky: solve failed (CHOLMOD status ", m.common.status, ")"));
  }
  Eigen::MatrixXd result =
      Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), m.n, rhs.cols());
  cholmod_free_dense(&x, &m.common);
  return result;
}

int SparseCholesky::rows() const { return impl_->n; }
bool SparseCholesky::factorized() const { return impl_->factorized; }

}  // namespace inbetween::solver
