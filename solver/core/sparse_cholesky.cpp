// CHOLMOD-backed sparse LDL^T (see sparse_cholesky.h). By default a simplicial factorization with
// an AMD ordering: no BLAS and no threads, so results are bit-identical run to run; solves are our
// own substitutions reading CHOLMOD's factor arrays in place (no copy, no allocation per solve).
// Method::kAuto lets CHOLMOD go supernodal on large matrices (its factorization runs on BLAS; the
// solves are our own substitutions over the supernodes, no BLAS).
#include "solver/core/sparse_cholesky.h"

#include <cholmod.h>
#include <dlfcn.h>
#include <sys/mman.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "solver/core/factorization_cancel_point.h"

namespace inbetween::solver {

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_factor* factor = nullptr;
  bool factorized = false;
  int n = 0;
  // The analyzed pattern, to check that Factorize gets the same structure.
  std::vector<int> outer;
  std::vector<int> inner;
  // P A P^T = L D L^T read in place from CHOLMOD's simplicial factor (no copy): column j holds
  // D_jj at x[p[j]], then the rows below the diagonal at i/x[p[j] + 1 .. p[j] + nz[j] - 1];
  // perm[k] = row of A at position k. Valid while `factor` is not changed.
  const int* perm = nullptr;
  const int* l_p = nullptr;
  const int* l_nz = nullptr;
  const int* l_i = nullptr;
  const double* l_x = nullptr;
  // P A P^T = L L^T from CHOLMOD's supernodal factor (in place): supernode s holds columns
  // [super[s], super[s + 1]) as a dense column-major block of nsrow = pi[s + 1] - pi[s] rows at
  // x[px[s]], its rows listed at s_i[pi[s] ..] (the first ones are the block's own columns).
  int nsuper = 0;
  const int* super = nullptr;
  const int* s_pi = nullptr;
  const int* s_px = nullptr;
  const int* s_i = nullptr;
  int max_below = 0;                           // most rows below a supernode's diagonal block
  mutable std::vector<double> work;            // interleaved right-hand sides, n x columns
  mutable std::vector<double> supernode_work;  // SubstituteSupernodal's scratch

  // The supernodal factorization's input S = tril(P A P^T), which cholmod_factorize would build by
  // a permuted transpose on every call (~0.2 s at 311k vertices, no poll possible inside): its
  // pattern is built once per analysis (BuildPermutedLower), each Factorize scatters A's values
  // into it in polled spans (lower_map[k]: position in lower_x of A's k-th stored value, -1 below
  // the diagonal, which is not read) and calls cholmod_super_numeric directly.
  std::vector<int> lower_p, lower_i, lower_map;
  std::vector<double> lower_x;
  void BuildPermutedLower();
  // Scatters a's values into lower_x, polling `cancel` every kScatterPoll values; false if set.
  bool ScatterPermutedLower(const Eigen::SparseMatrix<double>& a, const CancelToken* cancel);
  // A supernodal factor fresh from an analysis holds no values: cholmod_super_numeric allocates
  // them (cholmod_change_factor, as here) and their pages are first touched as it clears each
  // supernode, inside the one library call (at 311k vertices 50-144 ms at a stretch between two
  // of our BLAS hooks, the largest supernodes being last), and every analysis (one per topology
  // pass) did so again: the values are hundreds of MB there, so glibc maps them anew each time.
  // This gives the factor the previous factor's value array when it is large enough (its pages
  // are resident: CHOLMOD clears each supernode itself before using it), else a new one with
  // 1/8 more room (the exact size if that much is not available), whose pages it touches in polled
  // spans of kTouchPoll values when `cancel` is given. cholmod_super_numeric then finds the factor
  // numeric. 1 when done, 0 on a CHOLMOD error (common.status), -1 if cancelled (the factor is then
  // numeric with meaningless values, which the next Factorize overwrites like any
  // refactorization's).
  int AllocateSupernodalValues(const CancelToken* cancel);
  // Frees the factor, keeping a supernodal factor's value array as the spare for the next one.
  void FreeFactor();
  void FreeSpare() {
    if (spare_x != nullptr) cholmod_free(spare_capacity, sizeof(double), spare_x, &common);
    spare_x = nullptr;
    spare_capacity = 0;
  }
  void* spare_x = nullptr;
  size_t spare_capacity = 0;  // values
  size_t x_capacity = 0;      // values factor->x has room for (0: factor->xsize)

  void Extract();
  // The simplicial numeric factorization in row blocks of kCancelRows, polling `cancel` between
  // blocks: 1 on success (check common.status), 0 on a CHOLMOD error, -1 if cancelled.
  int FactorizeSimplicialInBlocks(cholmod_sparse* a, const CancelToken& cancel);
  // The substitutions poll `cancel` (may be null) every kSolveCancelStride columns of L
  // (simplicial) or supernodes and return false, y half solved, once it is set; true when done.
  template <int kColumns>
  bool Substitute(double* y, int columns, const CancelToken* cancel) const;
  template <int kColumns, typename T>
  bool SubstituteSupernodal(const T* values, double* y, int columns, double* below,
                            const CancelToken* cancel) const;
  bool float_substitutions = false;
  // With float_substitutions, a supernodal factor's values rounded to float, stored in place over
  // the first half of factor->x (so no memory is added; the doubles are gone until the next
  // Factorize, which overwrites every value anyway); null otherwise.
  const float* l_xf = nullptr;
  // Rounds the values to float in place (above), polling `cancel` every kConvertPoll values;
  // false if it was set (the values are then meaningless, as after a cancelled factorization).
  bool ConvertValuesToFloat(const CancelToken* cancel);
  // Solves in place for `columns` interleaved right-hand sides in the permuted order. `below`:
  // max_below x columns values of scratch (supernodal factors only).
  template <int kColumns>
  bool SolvePermuted(double* y, int columns, double* below, const CancelToken* cancel) const {
    if (super != nullptr) {
      if (l_xf != nullptr) return SubstituteSupernodal<kColumns>(l_xf, y, columns, below, cancel);
      return SubstituteSupernodal<kColumns>(l_x, y, columns, below, cancel);
    }
    return Substitute<kColumns>(y, columns, cancel);
  }

  explicit Impl(Method method);
  ~Impl() {
    FreeFactor();
    FreeSpare();
    cholmod_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

void SparseCholesky::Impl::BuildPermutedLower() {
  const int* p = static_cast<const int*>(factor->Perm);
  std::vector<int> inverse(n);
  for (int k = 0; k < n; ++k) inverse[p[k]] = k;
  const size_t nnz = inner.size();
  // Entry k of A (row i <= column j) goes to S(max, min) of the permuted indices. Bucketed by
  // S's row first, then placed column by column in row order: S's columns come out sorted.
  std::vector<int> row_of(nnz, -1), col_of(nnz, -1);
  std::vector<int> row_start(n + 1, 0);
  lower_p.assign(n + 1, 0);
  for (int j = 0; j < n; ++j) {
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      if (inner[k] > j) continue;
      const int a = inverse[inner[k]], b = inverse[j];
      row_of[k] = std::max(a, b);
      col_of[k] = std::min(a, b);
      ++row_start[row_of[k] + 1];
      ++lower_p[col_of[k] + 1];
    }
  }
  for (int r = 0; r < n; ++r) row_start[r + 1] += row_start[r];
  for (int c = 0; c < n; ++c) lower_p[c + 1] += lower_p[c];
  std::vector<int> by_row(row_start[n]);
  std::vector<int> next(row_start.begin(), row_start.end() - 1);
  for (size_t k = 0; k < nnz; ++k) {
    if (row_of[k] >= 0) by_row[next[row_of[k]]++] = static_cast<int>(k);
  }
  lower_i.assign(lower_p[n], 0);
  lower_x.assign(lower_p[n], 0.0);
  lower_map.assign(nnz, -1);
  next.assign(lower_p.begin(), lower_p.end() - 1);
  for (const int k : by_row) {
    const int at = next[col_of[k]]++;
    lower_i[at] = row_of[k];
    lower_map[k] = at;
  }
}

bool SparseCholesky::Impl::ScatterPermutedLower(const Eigen::SparseMatrix<double>& a,
                                                const CancelToken* cancel) {
  constexpr size_t kScatterPoll = size_t{1} << 20;
  const double* values = a.valuePtr();
  for (size_t begin = 0; begin < lower_map.size(); begin += kScatterPoll) {
    if (Cancelled(cancel)) return false;
    const size_t end = std::min(lower_map.size(), begin + kScatterPoll);
    for (size_t k = begin; k < end; ++k) {
      if (lower_map[k] >= 0) lower_x[lower_map[k]] = values[k];
    }
  }
  return true;
}

int SparseCholesky::Impl::AllocateSupernodalValues(const CancelToken* cancel) {
  constexpr size_t kTouchPoll = size_t{1} << 19;  // 4 MB of doubles
  // Allocates factor->xsize values (malloc, pages not touched yet).
  if (!cholmod_change_factor(CHOLMOD_REAL, /*to_ll=*/1, /*to_super=*/1, /*to_packed=*/1,
                             /*to_monotonic=*/1, factor, &common) ||
      common.status < CHOLMOD_OK) {
    return 0;
  }
  const size_t need = factor->xsize;
  if (spare_x != nullptr && spare_capacity >= need) {
    cholmod_free(need, sizeof(double), factor->x, &common);
    factor->x = spare_x;
    x_capacity = spare_capacity;
    spare_x = nullptr;
    spare_capacity = 0;
    return 1;
  }
  FreeSpare();
  const size_t capacity = need + need / 8;
  if (void* x = cholmod_malloc(capacity, sizeof(double), &common); x != nullptr) {
    cholmod_free(need, sizeof(double), factor->x, &common);
    factor->x = x;
    x_capacity = capacity;
  } else {
    common.status = CHOLMOD_OK;  // no room for the slack: the exact array CHOLMOD allocated
  }
  if (cancel == nullptr) return 1;
  double* values = static_cast<double*>(factor->x);
  for (size_t begin = 0; begin < need; begin += kTouchPoll) {
    if (cancel->IsCancelled()) return -1;
    std::fill(values + begin, values + std::min(need, begin + kTouchPoll), 0.0);
  }
  return 1;
}

void SparseCholesky::Impl::FreeFactor() {
  if (factor == nullptr) return;
  if (factor->is_super && factor->xtype != CHOLMOD_PATTERN && factor->x != nullptr) {
    FreeSpare();
    spare_x = factor->x;
    spare_capacity = std::max(x_capacity, factor->xsize);
    factor->x = nullptr;
  }
  x_capacity = 0;
  cholmod_free_factor(&factor, &common);
}

namespace {
absl::Status NumericCancelled() {
  return absl::CancelledError("SparseCholesky: numeric factorization cancelled");
}
}  // namespace

bool SparseCholesky::Impl::ConvertValuesToFloat(const CancelToken* cancel) {
  // Span by span: the span's doubles are read into a float buffer, then copied to bytes
  // [4 begin, 4 end) of the array, which lie below the unread doubles (from byte 8 end on).
  constexpr size_t kConvertPoll = size_t{1} << 20;
  const size_t count = static_cast<size_t>(s_px[nsuper]);
  char* bytes = static_cast<char*>(factor->x);
  std::vector<float> span(std::min(count, kConvertPoll));
  for (size_t begin = 0; begin < count; begin += kConvertPoll) {
    if (Cancelled(cancel)) return false;
    const size_t end = std::min(count, begin + kConvertPoll);
    for (size_t k = begin; k < end; ++k) span[k - begin] = static_cast<float>(l_x[k]);
    std::memcpy(bytes + begin * sizeof(float), span.data(), (end - begin) * sizeof(float));
  }
  l_xf = reinterpret_cast<const float*>(bytes);
  return true;
}

void SparseCholesky::Impl::Extract() {
  l_xf = nullptr;
  perm = static_cast<const int*>(factor->Perm);
  l_x = static_cast<const double*>(factor->x);
  if (factor->is_super) {
    nsuper = static_cast<int>(factor->nsuper);
    super = static_cast<const int*>(factor->super);
    s_pi = static_cast<const int*>(factor->pi);
    s_px = static_cast<const int*>(factor->px);
    s_i = static_cast<const int*>(factor->s);
    l_p = l_nz = l_i = nullptr;
    max_below = 0;
    for (int k = 0; k < nsuper; ++k) {
      max_below = std::max(max_below, (s_pi[k + 1] - s_pi[k]) - (super[k + 1] - super[k]));
    }
  } else {
    l_p = static_cast<const int*>(factor->p);
    l_nz = static_cast<const int*>(factor->nz);
    l_i = static_cast<const int*>(factor->i);
    super = s_pi = s_px = s_i = nullptr;
    nsuper = max_below = 0;
  }
}

namespace {

// Columns of a supernode handled side by side (kGroup at a time); every entry of y and of the
// scratch still sees its operations in the same order as one column at a time, so the result is
// bit-identical to that.
constexpr int kGroup = 4;

// One supernode of a supernodal factor: its first column k1, nscol columns, nsrow rows (the
// diagonal block's nscol, then nbelow rows listed in `rows`), values column-major in `block`.
template <typename T>
struct Supernode {
  int k1, nscol, nsrow, nbelow;
  const int* rows;
  const T* block;
};

// L z = y on one supernode: the diagonal block in place, then the rows below through `below`
// (`columns` right-hand sides interleaved), gathered once and scattered into y.
template <int kColumns, typename T>
void ForwardSupernode(const Supernode<T>& sn, double* y, int columns, double* below) {
  const int c = kColumns > 0 ? kColumns : columns;  // a constant where the caller's is
  const int nscol = sn.nscol, nsrow = sn.nsrow, nbelow = sn.nbelow;
  double* ys = y + static_cast<size_t>(sn.k1) * c;
  std::fill(below, below + static_cast<size_t>(nbelow) * c, 0.0);
  for (int j0 = 0; j0 < nscol; j0 += kGroup) {
    const int group = std::min(kGroup, nscol - j0);
    for (int j = j0; j < j0 + group; ++j) {
      const T* col = sn.block + static_cast<size_t>(j) * nsrow;
      double* yj = ys + static_cast<size_t>(j) * c;
      const double inv = 1.0 / col[j];
      for (int q = 0; q < c; ++q) yj[q] *= inv;
      for (int i = j + 1; i < nscol; ++i) {
        for (int q = 0; q < c; ++q) ys[static_cast<size_t>(i) * c + q] -= col[i] * yj[q];
      }
    }
    // below += lower_j * y_j for the group's columns in column order, one pass over `below`.
    const T* lower = sn.block + static_cast<size_t>(j0) * nsrow + nscol;
    const double* yg = ys + static_cast<size_t>(j0) * c;
    if (group == kGroup) {
      for (int r = 0; r < nbelow; ++r) {
        for (int q = 0; q < c; ++q) {
          double acc = below[static_cast<size_t>(r) * c + q];
          for (int g = 0; g < kGroup; ++g) acc += lower[r + g * nsrow] * yg[g * c + q];
          below[static_cast<size_t>(r) * c + q] = acc;
        }
      }
      continue;
    }
    for (int g = 0; g < group; ++g) {
      for (int r = 0; r < nbelow; ++r) {
        for (int q = 0; q < c; ++q) {
          below[static_cast<size_t>(r) * c + q] += lower[r + g * nsrow] * yg[g * c + q];
        }
      }
    }
  }
  for (int r = 0; r < nbelow; ++r) {
    double* yr = y + static_cast<size_t>(sn.rows[r]) * c;
    for (int q = 0; q < c; ++q) yr[q] -= below[static_cast<size_t>(r) * c + q];
  }
}

// L^T x = z on one supernode: the rows below gathered into `below`, then the diagonal block from
// its last column back, each column's dot product with `below` first.
template <int kColumns, typename T>
void BackwardSupernode(const Supernode<T>& sn, double* y, int columns, double* below) {
  const int c = kColumns > 0 ? kColumns : columns;  // a constant where the caller's is
  const int nscol = sn.nscol, nsrow = sn.nsrow, nbelow = sn.nbelow;
  double* ys = y + static_cast<size_t>(sn.k1) * c;
  for (int r = 0; r < nbelow; ++r) {
    const double* yr = y + static_cast<size_t>(sn.rows[r]) * c;
    for (int q = 0; q < c; ++q) below[static_cast<size_t>(r) * c + q] = yr[q];
  }
  for (int j1 = nscol; j1 > 0; j1 -= kGroup) {
    const int group = std::min(kGroup, j1), j0 = j1 - group;
    const T* lower = sn.block + static_cast<size_t>(j0) * nsrow + nscol;
    const size_t stride = static_cast<size_t>(nsrow);
    for (int q = 0; q < c; ++q) {  // right-hand sides are independent
      // Each column's dot product with `below` (one sum per column, in row order), the
      // group's columns side by side: independent sums, one pass over `below`.
      double sums[kGroup] = {0.0, 0.0, 0.0, 0.0};
      if (group == kGroup) {
        for (int r = 0; r < nbelow; ++r) {
          const double b = below[static_cast<size_t>(r) * c + q];
          sums[0] += lower[r] * b;
          sums[1] += lower[r + stride] * b;
          sums[2] += lower[r + 2 * stride] * b;
          sums[3] += lower[r + 3 * stride] * b;
        }
      } else {
        for (int g = 0; g < group; ++g) {
          for (int r = 0; r < nbelow; ++r) {
            sums[g] += lower[r + g * stride] * below[static_cast<size_t>(r) * c + q];
          }
        }
      }
      for (int j = j1 - 1; j >= j0; --j) {
        const T* col = sn.block + static_cast<size_t>(j) * nsrow;
        double sum = sums[j - j0];
        for (int i = j + 1; i < nscol; ++i) sum += col[i] * ys[static_cast<size_t>(i) * c + q];
        double& yj = ys[static_cast<size_t>(j) * c + q];
        yj = (yj - sum) / col[j];
      }
    }
  }
}

}  // namespace

// The supernodal twin of Substitute (L L^T, no D): per supernode, the dense diagonal block in
// place, and the rows below it through a dense scratch (gathered or scattered once per supernode,
// so the inner loops run over contiguous memory); no BLAS, so solves on several threads never
// contend. `below`: scratch of max_below x columns values. `values`: the factor's values, l_x or
// their float rounding (l_xf); products and sums are in double either way.
template <int kColumns, typename T>
bool SparseCholesky::Impl::SubstituteSupernodal(const T* values, double* y, int columns,
                                                double* below, const CancelToken* cancel) const {
  const int c = kColumns > 0 ? kColumns : columns;
  constexpr size_t kSolvePollEntries = size_t{1} << 18;  // ~2 MB of L: about a millisecond
  // Polled every kSolveCancelStride supernodes and, in between, whenever kSolvePollEntries of
  // L's entries were read since the last poll (the supernodes near the root are large).
  size_t entries = 0;
  auto poll = [&](int s, int nsrow, int nscol) {
    entries += static_cast<size_t>(nsrow) * nscol;
    if (s % kSolveCancelStride != 0 && entries < kSolvePollEntries) return false;
    entries = 0;
    return Cancelled(cancel);
  };
  auto supernode = [&](int s) {
    const int k1 = super[s], nscol = super[s + 1] - k1;
    const int nsrow = s_pi[s + 1] - s_pi[s];
    return Supernode<T>{k1, nscol, nsrow, nsrow - nscol, s_i + s_pi[s] + nscol, values + s_px[s]};
  };
  for (int s = 0; s < nsuper; ++s) {  // L z = y
    const Supernode<T> sn = supernode(s);
    if (poll(s, sn.nsrow, sn.nscol)) return false;
    ForwardSupernode<kColumns>(sn, y, c, below);
  }
  for (int s = nsuper - 1; s >= 0; --s) {  // L^T x = z
    const Supernode<T> sn = supernode(s);
    if (poll(s, sn.nsrow, sn.nscol)) return false;
    BackwardSupernode<kColumns>(sn, y, c, below);
  }
  return true;
}

// y: n rows of `columns` interleaved values (kColumns == columns, or 0 for any count).
template <int kColumns>
bool SparseCholesky::Impl::Substitute(double* y, int columns, const CancelToken* cancel) const {
  const int c = kColumns > 0 ? kColumns : columns;
  for (int j = 0; j < n; ++j) {  // L z = y, column oriented
    if (j % kSolveCancelStride == 0 && Cancelled(cancel)) return false;
    const double* yj = y + static_cast<size_t>(j) * c;
    const int end = l_p[j] + l_nz[j];
    for (int k = l_p[j] + 1; k < end; ++k) {
      double* yi = y + static_cast<size_t>(l_i[k]) * c;
      const double l = l_x[k];
      for (int q = 0; q < c; ++q) yi[q] -= l * yj[q];
    }
  }
  for (int j = 0; j < n; ++j) {
    const double inv = 1.0 / l_x[l_p[j]];
    for (int q = 0; q < c; ++q) y[static_cast<size_t>(j) * c + q] *= inv;
  }
  for (int j = n - 1; j >= 0; --j) {  // L^T x = z, dot products with L's columns
    if (j % kSolveCancelStride == 0 && Cancelled(cancel)) return false;
    double* yj = y + static_cast<size_t>(j) * c;
    const int end = l_p[j] + l_nz[j];
    for (int k = l_p[j] + 1; k < end; ++k) {
      const double* yi = y + static_cast<size_t>(l_i[k]) * c;
      const double l = l_x[k];
      for (int q = 0; q < c; ++q) yj[q] -= l * yi[q];
    }
  }
  return true;
}

namespace {

// Supernodal factorizations call the system BLAS (Debian's alternative for libblas.so.3; the
// solves are our own substitutions). Reentrancy: OpenBLAS's serial build (libopenblas0-serial,
// openblas_get_parallel() == 0) is not reentrant: two concurrent factorizations of positive
// definite matrices failed with "not positive definite" (measured). Only then do the BLAS-using
// calls take one process-wide lock; the pthread and OpenMP builds, BLIS and the reference BLAS run
// concurrently (measured: the pthread build passed
// SparseCholeskyTest.ConcurrentSupernodalFactorizationsAreCorrect 8 of 8 times unlocked, the
// serial one failed 6 of 6). Simplicial factors use no BLAS. The BLAS's own thread count is the
// program's to set (process_overrides.cpp pins OpenBLAS to one thread in our executables).
struct BlasSetup {
  bool serialize = false;
};

const BlasSetup& Blas() {
  static const BlasSetup setup = [] {
    using GetParallel = int (*)();
    auto* get = reinterpret_cast<GetParallel>(dlsym(RTLD_DEFAULT, "openblas_get_parallel"));
    return BlasSetup{.serialize = get != nullptr && get() == 0};
  }();
  return setup;
}

// kCancelPoint: a supernodal factorization (CHOLMOD's cholmod_super_numeric) has no callback, but
// it calls LAPACK's dpotrf_ once per supernode, on the supernode's dense diagonal block, and stops
// as soon as one reports that block not positive definite at its first column (info == 1: the
// status becomes CHOLMOD_NOT_POSDEF). Programs that link inbetween_process_overrides
// (process_overrides.cpp: our CLI, server, benches and tests) define dpotrf_ and the BLAS-3
// routines CHOLMOD calls, and ask this file, through factorization_cancel_point.h, whether the
// calling thread's factorization is cancelled: the BLAS routines then do nothing and dpotrf_
// answers info = 1, and Factorize below reports the cancellation, not a failed pivot. Before
// returning, CHOLMOD zeroes the values of the factor from that supernode to the end (L->x up to
// L->xsize: at 73k vertices, tens of MB of memory not touched yet, 50-80 ms measured); the stop
// sets L->xsize to 0 for that moment (the zeroing loop then does nothing) and Factorize restores
// it as soon as CHOLMOD returns. The factor's values are then meaningless, which is what "not
// factorized" already says: the next Factorize writes every supernode anew. Without the
// overrides a supernodal factorization runs to its end once started, and the cancellation is
// seen at the next poll after it.
thread_local const CancelToken* tls_factor_cancel = nullptr;
thread_local cholmod_factor* tls_factor = nullptr;
thread_local bool tls_factor_cancelled = false;
thread_local size_t tls_factor_xsize = 0;
thread_local bool tls_factor_xsize_taken = false;

// Sets the calling thread's cancellation token and factor for the scope of one supernodal
// factorization; on leaving it, gives the factor back its xsize if the hook took it.
class CancelPointScope {
 public:
  CancelPointScope(const CancelToken* cancel, cholmod_factor* factor) {
    tls_factor_cancel = cancel;
    tls_factor = factor;
  }
  ~CancelPointScope() {
    if (tls_factor_xsize_taken && tls_factor != nullptr) tls_factor->xsize = tls_factor_xsize;
    tls_factor_cancel = nullptr;
    tls_factor = nullptr;
    // The BLAS hooks skip their work while this is set: it must not outlive the factorization.
    tls_factor_cancelled = false;
    tls_factor_xsize_taken = false;
  }
  CancelPointScope(const CancelPointScope&) = delete;
  CancelPointScope& operator=(const CancelPointScope&) = delete;
};

// Held around a call that uses BLAS (`uses_blas`) when the BLAS is not reentrant (see above).
class BlasLock {
 public:
  explicit BlasLock(bool uses_blas) : lock_(Mutex(), std::defer_lock) {
    if (uses_blas && Blas().serialize) lock_.lock();
  }

 private:
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  std::unique_lock<std::mutex> lock_;
};

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

// CHOLMOD's out-of-memory (malloc returned NULL) and too-large (size_t overflow) statuses are
// RESOURCE_EXHAUSTED, so that callers can tell them from a matrix that is not SPD.
absl::Status CholmodError(const cholmod_common& common, const char* step) {
  const std::string what = absl::StrCat("SparseCholesky: ", step);
  if (common.status == CHOLMOD_OUT_OF_MEMORY) {
    return absl::ResourceExhaustedError(absl::StrCat(what, " ran out of memory"));
  }
  if (common.status == CHOLMOD_TOO_LARGE) {
    return absl::ResourceExhaustedError(absl::StrCat(what, ": the problem is too large"));
  }
  return absl::InternalError(absl::StrCat(what, " failed (CHOLMOD status ", common.status, ")"));
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

SparseCholesky::Impl::Impl(Method method) {
  cholmod_start(&common);
  common.print = 0;  // errors come back as absl::Status, not on stderr
  common.supernodal = method == Method::kAuto         ? CHOLMOD_AUTO
                      : method == Method::kSupernodal ? CHOLMOD_SUPERNODAL
                                                      : CHOLMOD_SIMPLICIAL;
  common.final_ll = false;
  // Supernodal from flops / nnz(L) >= 100 (CHOLMOD's default switch is 40): on the comesh
  // Hessians (2 unknowns per vertex) the simplicial factor with our substitutions is faster up to
  // the 8.6k-vertex row of S-Table 2 (at 40 the 2k and 4k rows took ~10% longer), the supernodal
  // one from 17k (~9% less time there than at 200, with CHOLMOD's OpenMP teams gone: see
  // GOMP_parallel in process_overrides.cpp and docs/benchmarks.md).
  common.supernodal_switch = 100.0;
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_AMD;
  common.postorder = true;
}

SparseCholesky::SparseCholesky(Method method) : impl_(std::make_unique<Impl>(method)) {}
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;
SparseCholesky::~SparseCholesky() = default;

absl::Status SparseCholesky::Analyze(const Eigen::SparseMatrix<double>& a,
                                     const std::vector<int>* ordering) {
  if (absl::Status s = CheckShape(a); !s.ok()) return s;
  if (ordering != nullptr) {
    std::vector<char> seen(a.rows(), 0);
    bool valid = static_cast<Eigen::Index>(ordering->size()) == a.rows();
    for (size_t k = 0; valid && k < ordering->size(); ++k) {
      const int row = (*ordering)[k];
      valid = row >= 0 && row < a.rows() && !seen[row];
      if (valid) seen[row] = 1;
    }
    if (!valid) {
      return absl::InvalidArgumentError(
          absl::StrCat("SparseCholesky: the ordering is not a permutation of 0..", a.rows() - 1));
    }
  }
  Impl& m = *impl_;
  m.FreeFactor();
  m.factorized = false;
  m.n = static_cast<int>(a.rows());
  m.outer.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.cols() + 1);
  m.inner.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  cholmod_sparse view = View(a);
  if (ordering != nullptr) {
    const int amd = m.common.method[0].ordering;
    m.common.method[0].ordering = CHOLMOD_GIVEN;
    m.factor = cholmod_analyze_p(&view, const_cast<int*>(ordering->data()), nullptr, 0, &m.common);
    m.common.method[0].ordering = amd;
  } else {
    m.factor = cholmod_analyze(&view, &m.common);
  }
  if (m.factor == nullptr || m.common.status < CHOLMOD_OK) {
    return CholmodError(m.common, "symbolic analysis");
  }
  m.lower_p.clear();
  m.lower_i.clear();
  m.lower_x.clear();
  m.lower_map.clear();
  if (m.factor->is_super) m.BuildPermutedLower();
  return absl::OkStatus();
}

absl::Status SparseCholesky::Factorize(const Eigen::SparseMatrix<double>& a,
                                       const CancelToken* cancel) {
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
  auto cancelled = [] { return NumericCancelled(); };
  // (No early return for a token already set: the first poll, at the first row block or the
  // first supernode, answers then; the tests rely on that to reach both polls.)
  cholmod_sparse view = View(a);
  int ok = 0;
  if (cancel != nullptr && m.factor->is_super == 0) {
    // What cholmod_factorize does for a simplicial factor of a symmetric-upper matrix (with
    // final_asis, our setting: no conversion afterwards), with cholmod_rowfac called on blocks of
    // rows instead of all rows at once: row k only reads rows < k, so the factor is the same.
    ok = m.FactorizeSimplicialInBlocks(&view, *cancel);
    if (ok < 0) return cancelled();
  } else {
    const bool super = m.factor->is_super != 0;
    if (super && !m.ScatterPermutedLower(a, cancel)) return cancelled();
    if (super && m.factor->xtype == CHOLMOD_PATTERN) {
      const int allocated = m.AllocateSupernodalValues(cancel);
      if (allocated < 0) return cancelled();
      if (allocated == 0) return CholmodError(m.common, "numeric factorization");
    }
    const BlasLock blas(/*uses_blas=*/super);
    bool stopped = false;
    {
      const CancelPointScope scope(super ? cancel : nullptr, m.factor);
      if (super) {
        // What cholmod_factorize does for a supernodal factor of a symmetric-upper matrix (with
        // final_asis: no conversion afterwards), S = tril(P A P^T) being ready.
        cholmod_sparse lower{};
        lower.nrow = lower.ncol = static_cast<size_t>(m.n);
        lower.nzmax = m.lower_x.size();
        lower.p = m.lower_p.data();
        lower.i = m.lower_i.data();
        lower.x = m.lower_x.data();
        lower.stype = -1;
        lower.itype = CHOLMOD_INT;
        lower.xtype = CHOLMOD_REAL;
        lower.dtype = CHOLMOD_DOUBLE;
        lower.sorted = 1;
        lower.packed = 1;
        double beta[2] = {0.0, 0.0};
        m.common.status = CHOLMOD_OK;
        ok = cholmod_super_numeric(&lower, nullptr, beta, m.factor, &m.common);
      } else {
        ok = cholmod_factorize(&view, m.factor, &m.common);
      }
      stopped = tls_factor_cancelled;
    }
    if (stopped) return cancelled();
  }
  if (!ok || m.common.status < CHOLMOD_OK) {
    return CholmodError(m.common, "numeric factorization");
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
  m.Extract();
  if (m.float_substitutions && m.super != nullptr && !m.ConvertValuesToFloat(cancel)) {
    return NumericCancelled();
  }
  m.factorized = true;
  return absl::OkStatus();
}

int SparseCholesky::Impl::FactorizeSimplicialInBlocks(cholmod_sparse* a,
                                                      const CancelToken& cancel) {
  common.status = CHOLMOD_OK;
  const int rows = static_cast<int>(factor->n);
  // S = triu(P A P^T): two permuted transposes, as cholmod_factorize_p does for stype > 0.
  cholmod_sparse* s = a;
  if (factor->ordering != CHOLMOD_NATURAL) {
    cholmod_sparse* lower =
        cholmod_ptranspose(a, 2, static_cast<int*>(factor->Perm), nullptr, 0, &common);
    if (lower == nullptr) return 0;
    s = cholmod_ptranspose(lower, 2, nullptr, nullptr, 0, &common);
    cholmod_free_sparse(&lower, &common);
    if (s == nullptr) return 0;
  }
  factor->is_ll = common.final_ll ? 1 : 0;
  if (factor->xtype != CHOLMOD_PATTERN) {
    // A refactorization: cholmod_rowfac restarts the factor (every column back to its diagonal
    // entry, no failed pivot yet) only when one call covers all rows, so do that here.
    factor->minor = factor->n;
    int* column_counts = static_cast<int*>(factor->nz);
    std::fill(column_counts, column_counts + rows, 1);
  }
  const double grow2 = common.grow2;
  if (factor->xtype == CHOLMOD_PATTERN && common.final_pack) common.grow2 = 0;
  double beta[2] = {0.0, 0.0};
  int result = 1;
  for (int k = 0; k < rows; k += kCancelRows) {
    if (cancel.IsCancelled()) {
      result = -1;
      break;
    }
    const int end = std::min(rows, k + kCancelRows);
    if (!cholmod_rowfac(s, nullptr, beta, k, end, factor, &common) || common.status < CHOLMOD_OK) {
      result = 0;
      break;
    }
  }
  common.grow2 = grow2;
  if (s != a) cholmod_free_sparse(&s, &common);
  return result;
}

absl::StatusOr<std::vector<int>> SparseCholesky::AmdOrdering(const std::vector<int>& outer,
                                                             const std::vector<int>& inner) {
  if (outer.empty() || outer.front() != 0 || outer.back() != static_cast<int>(inner.size()) ||
      !std::is_sorted(outer.begin(), outer.end())) {
    return absl::InvalidArgumentError("SparseCholesky::AmdOrdering: bad column starts");
  }
  const int n = static_cast<int>(outer.size()) - 1;
  for (int row : inner) {
    if (row < 0 || row >= n) {
      return absl::InvalidArgumentError("SparseCholesky::AmdOrdering: row index out of range");
    }
  }
  std::vector<int> ordering(n);
  if (n == 0) return ordering;
  cholmod_common common;
  cholmod_start(&common);
  common.print = 0;
  cholmod_sparse pattern{};
  pattern.nrow = pattern.ncol = static_cast<size_t>(n);
  pattern.nzmax = inner.size();
  pattern.p = const_cast<int*>(outer.data());
  pattern.i = const_cast<int*>(inner.data());
  pattern.stype = 1;  // symmetric, upper triangle read (entries below are ignored)
  pattern.itype = CHOLMOD_INT;
  pattern.xtype = CHOLMOD_PATTERN;
  pattern.dtype = CHOLMOD_DOUBLE;
  pattern.sorted = 0;
  pattern.packed = 1;
  const int ok = cholmod_amd(&pattern, nullptr, 0, ordering.data(), &common);
  const cholmod_common copy = common;
  cholmod_finish(&common);
  if (!ok || copy.status < CHOLMOD_OK) return CholmodError(copy, "AMD ordering");
  return ordering;
}

absl::Status SparseCholesky::Compute(const Eigen::SparseMatrix<double>& a) {
  if (absl::Status s = Analyze(a); !s.ok()) return s;
  return Factorize(a);
}

namespace {
absl::Status SolveCancelled() { return absl::CancelledError("SparseCholesky: solve cancelled"); }
}  // namespace

absl::StatusOr<Eigen::MatrixXd> SparseCholesky::Solve(const Eigen::MatrixXd& b) const {
  Eigen::MatrixXd x = b;
  if (absl::Status s = SolveInPlace(&x); !s.ok()) return s;
  return x;
}

absl::Status SparseCholesky::SolveInPlace(Eigen::MatrixXd* b, int threads,
                                          const CancelToken* cancel) const {
  const Impl& m = *impl_;
  if (!m.factorized) {
    return absl::FailedPreconditionError("SparseCholesky: Solve before a successful Factorize");
  }
  if (b->rows() != m.n) {
    return absl::InvalidArgumentError(
        absl::StrCat("SparseCholesky: right-hand side has ", b->rows(), " rows, matrix has ", m.n));
  }
  const int c = static_cast<int>(b->cols());
  if (c == 0) return absl::OkStatus();
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int workers = std::min(threads, c);
  m.work.resize(static_cast<size_t>(m.n) * c);
  double* y = m.work.data();
  // Scratch for the supernodal substitution: one column's worth per worker, or c columns.
  m.supernode_work.resize(static_cast<size_t>(m.max_below) * std::max(workers, c));
  if (workers > 1 && m.n >= kParallelRows) {
    // Column q in its own contiguous block of `work`, columns dealt round-robin to the workers.
    std::atomic<bool> stopped{false};
    auto run = [&](int worker) {
      for (int q = worker; q < c; q += workers) {
        double* yq = y + static_cast<size_t>(q) * m.n;
        for (int k = 0; k < m.n; ++k) yq[k] = (*b)(m.perm[k], q);
        if (!m.SolvePermuted<1>(yq, 1,
                                m.supernode_work.data() + static_cast<size_t>(worker) * m.max_below,
                                cancel)) {
          stopped = true;
          return;
        }
        for (int k = 0; k < m.n; ++k) (*b)(m.perm[k], q) = yq[k];
      }
    };
    std::vector<std::thread> pool;
    for (int w = 1; w < workers; ++w) pool.emplace_back(run, w);
    run(0);
    for (std::thread& t : pool) t.join();
    return stopped ? SolveCancelled() : absl::OkStatus();
  }
  for (int k = 0; k < m.n; ++k) {
    for (int q = 0; q < c; ++q) y[static_cast<size_t>(k) * c + q] = (*b)(m.perm[k], q);
  }
  bool done;
  switch (c) {
    case 1:
      done = m.SolvePermuted<1>(y, c, m.supernode_work.data(), cancel);
      break;
    case 2:
      done = m.SolvePermuted<2>(y, c, m.supernode_work.data(), cancel);
      break;
    default:
      done = m.SolvePermuted<0>(y, c, m.supernode_work.data(), cancel);
  }
  if (!done) return SolveCancelled();
  for (int k = 0; k < m.n; ++k) {
    for (int q = 0; q < c; ++q) (*b)(m.perm[k], q) = y[static_cast<size_t>(k) * c + q];
  }
  return absl::OkStatus();
}

int SparseCholesky::rows() const { return impl_->n; }
bool SparseCholesky::factorized() const { return impl_->factorized; }
void SparseCholesky::set_float_substitutions(bool on) { impl_->float_substitutions = on; }
bool SparseCholesky::supernodal() const {
  return impl_->factor != nullptr && impl_->factor->is_super;
}

namespace internal {

bool SupernodalFactorizationCancelled() {
  if (tls_factor_cancelled) return true;
  if (!Cancelled(tls_factor_cancel)) return false;
  tls_factor_cancelled = true;
  return true;
}

void StopSupernodalFactorizationHere(int* info) {
  if (!tls_factor_xsize_taken && tls_factor != nullptr) {
    tls_factor_xsize = tls_factor->xsize;
    tls_factor->xsize = 0;  // CHOLMOD's zeroing of the rest: nothing to do
    tls_factor_xsize_taken = true;
  }
  *info = 1;  // "not positive definite at the block's first column"
}

}  // namespace internal

}  // namespace inbetween::solver
