// Sparse SPD solver backend: A = L D L^T (CHOLMOD, SuiteSparse) behind one small pimpl class, so
// that nothing else includes cholmod.h. The fill-reducing ordering and symbolic factorization are
// computed once (Analyze); the numeric factorization can be redone for new values on the same
// pattern (Factorize), e.g. the per-frame matrix sum_i w_i K_i of the inbetweening global step.
// Solves with the factor P A P^T = L D L^T are our own forward/backward substitutions over
// CHOLMOD's factor arrays, all right-hand sides in one sweep over L (interleaved), with no
// allocation per solve in SolveInPlace: the inbetweener's global step is one such solve with 2
// columns per iteration.
//
// Method::kAuto lets CHOLMOD choose a supernodal LL^T factor when the matrix is large enough for
// dense kernels to pay (flops / nnz(L) >= 100; CHOLMOD's own switch is 40, but our simplicial
// substitutions were faster below 100 on the comesh Hessians; else the same simplicial factor): a
// supernodal factorization runs on BLAS (scripts/setup installs Debian's OpenBLAS, pthread build),
// measured 2.6 s against 70 s simplicial for a 320k-unknown planar mesh matrix
// (docs/benchmarks.md). Its solves are our own substitutions over the supernodes' dense blocks
// (no BLAS: solves on several threads never contend for OpenBLAS's buffer lock). A fixed
// ordering keeps the result bit-identical run to run on one machine. Objects on different threads
// factor and solve concurrently (with a non-reentrant BLAS, the serial OpenBLAS, those calls are
// serialized).
//
// Programs that link inbetween_process_overrides (process_overrides.cpp; our executables do)
// also get: OpenBLAS pinned to one thread (results independent of the machine's core count),
// CHOLMOD's OpenMP regions run on the calling thread (a factorization never starts threads of its
// own), huge pages for CHOLMOD's large arrays, and a cancelled supernodal factorization that stops
// within one dense panel instead of at its end (docs/install.md, "Process-wide overrides").
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "solver/core/cancel.h"

namespace inbetween::solver {

class SparseCholesky {
 public:
  // kSupernodal: always supernodal, for a pattern factored once per solve (the map's SLIM proxy:
  // at 3.3k and 23k unknowns ~1.5x faster than the simplicial factor kAuto picks there).
  enum class Method { kSimplicial, kAuto, kSupernodal };
  explicit SparseCholesky(Method method = Method::kSimplicial);
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;
  ~SparseCholesky();

  // Symbolic analysis of the pattern of `a` (square; only the upper triangle, diagonal included,
  // is read, so a full symmetric matrix may be passed). Forgets any previous factorization, but
  // keeps a supernodal factor's value array for the next one when it is large enough (its pages
  // stay mapped: hundreds of MB at 311k comesh vertices), so reuse one object across analyses.
  // The fill-reducing ordering is CHOLMOD's AMD on `a`, or `ordering` when given: a permutation of
  // 0 .. rows-1, ordering[k] = the row eliminated k-th (CHOLMOD then only postorders it).
  absl::Status Analyze(const Eigen::SparseMatrix<double>& a,
                       const std::vector<int>* ordering = nullptr);

  // AMD ordering (CHOLMOD's) of the symmetric pattern given by a compressed-column structure
  // (outer: n + 1 column starts, inner: the rows of each column, both triangles or one), for
  // callers that order a smaller graph and expand it (e.g. one node per mesh vertex instead of
  // one per unknown: the same elimination order for the 2 unknowns of a vertex, found on a
  // graph with a quarter of the entries).
  static absl::StatusOr<std::vector<int>> AmdOrdering(const std::vector<int>& outer,
                                                      const std::vector<int>& inner);

  // Numeric factorization of `a`, which must have exactly the analyzed pattern (same compressed
  // structure). FailedPrecondition if `a` is not positive definite. Analyze and Factorize answer
  // RESOURCE_EXHAUSTED when CHOLMOD runs out of memory (it reports, never throws). With a `cancel`
  // token the factorization polls it as it goes and answers CANCELLED soon after it is set (then
  // the object is not factorized; Factorize again to use it): a simplicial factor is computed in
  // row blocks of kCancelRows rows (CHOLMOD's incremental row factorization, the same operations in
  // the same order, so the factor is bit-identical to an uncancellable one), a supernodal one, in
  // programs that link inbetween_process_overrides, stops at the next supernode or, in a supernode
  // of 2 * kDensePanel columns or more, at the next panel of kDensePanel columns (see kCancelPoint
  // in the .cpp; without them it runs to its end); the first one after an analysis also while its
  // value array is allocated and its pages touched, per 4 MB.
  absl::Status Factorize(const Eigen::SparseMatrix<double>& a, const CancelToken* cancel = nullptr);
  static constexpr int kCancelRows = 256;
  static constexpr int kDensePanel = 256;

  // Analyze + Factorize.
  absl::Status Compute(const Eigen::SparseMatrix<double>& a);

  // Solves A X = B for all columns of B. FailedPrecondition before a successful Factorize.
  absl::StatusOr<Eigen::MatrixXd> Solve(const Eigen::MatrixXd& b) const;

  // Overwrites the columns of *b (rows() rows, any number of columns) with the solution.
  // Allocation-free after the first call with a given column count. Uses internal scratch, so
  // one object must not solve on two threads at once. With threads > 1 (<= 0: all cores) and at
  // least kParallelRows rows, the columns are substituted separately on up to `threads` threads;
  // each column sees the same operations in the same order either way, so the result is
  // bit-identical for every thread count (supernodal factors too).
  // With a `cancel` token the substitutions poll it every kSolveCancelStride columns of L
  // (simplicial) or supernodes and answer CANCELLED soon after it is set, leaving *b partly
  // solved (a 2x311k-unknown comesh direction solve takes ~0.2 s, more than a cancel may wait).
  absl::Status SolveInPlace(Eigen::MatrixXd* b, int threads = 1,
                            const CancelToken* cancel = nullptr) const;
  static constexpr int kParallelRows = 8192;
  static constexpr int kSolveCancelStride = 256;

  // Single-precision substitutions (for preconditioners, where L to 1e-16 buys nothing): each
  // factorization of a supernodal factor ends by rounding its values to float, in place (no
  // memory added; polled like the factorization), and the solves read those (products and sums
  // still in double). The substitutions read L once per sweep and are bound by memory traffic,
  // so halving L's bytes made the comesh direction ~27% faster per iteration at 165k vertices
  // (docs/benchmarks.md). Simplicial factors are unaffected. Takes effect at the next Factorize.
  void set_float_substitutions(bool on);

  int rows() const;
  bool factorized() const;
  bool supernodal() const;  // after Analyze: CHOLMOD chose a supernodal factor

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace inbetween::solver
