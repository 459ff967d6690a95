// Process-wide overrides that our executables link (the CLI, the server, the load generator, the
// benches and the tests: the CMake target inbetween_process_overrides) and the solver library does
// not need. Each changes the whole process, which a library must not do to the program that links
// it, and each buys speed or a prompt cancellation, not correctness:
// - dpotrf_, dsyrk_, dgemm_, dtrsm_: LAPACK's and the BLAS's routines as CHOLMOD calls them,
//   forwarded to the next definition, large dense blocks in panels with a poll between them, so a
//   cancelled supernodal factorization stops within one panel's work (kCancelPoint in
//   sparse_cholesky.cpp). A definition in the executable comes before the libraries' for the
//   dynamic linker, so CHOLMOD's calls bind here.
// - GOMP_parallel: CHOLMOD's OpenMP regions run on the calling thread (below).
// - OpenBLAS pinned to one thread, and SuiteSparse's allocator asking for transparent huge pages
//   (kSetUpAtLoad).
// A program without them gets the same factors from the simplicial path and from supernodes
// narrower than 2 * kDensePanel columns; wider supernodes are factored by the system LAPACK in one
// call, whose blocking may round differently. The trade is documented in docs/install.md.
#include <cholmod.h>
#include <dlfcn.h>
#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "solver/core/factorization_cancel_point.h"
#include "solver/core/sparse_cholesky.h"

// LAPACK's Cholesky factorization of a dense block, as CHOLMOD calls it (32-bit BLAS integers; the
// trailing length of the character argument that gfortran-built LAPACKs take is passed through).
// kCancelPoint in sparse_cholesky.cpp explains why this file defines it.
extern "C" void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info,
                        size_t uplo_length);
extern "C" void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k,
                       const double* alpha, const double* a, const int* lda, const double* beta,
                       double* c, const int* ldc, size_t uplo_length, size_t trans_length);

namespace inbetween::solver {
namespace {

// CHOLMOD's large arrays (a supernodal factor's values: 34 MB for a 35k-vertex comesh shape,
// hundreds of MB beyond) come from glibc's mmap path, fresh zero pages every time, and every 4 KiB
// page costs a fault when first written (perf: 14% of the 35k-vertex row of S-Table 2; on a
// cancelled factorization CHOLMOD zeroes the unfactored rest, faulting it all in). SuiteSparse
// allocates through SuiteSparse_config's function pointers; ours ask the kernel for transparent
// huge pages (madvise MADV_HUGEPAGE: 2 MiB pages, 512 times fewer faults) on blocks of
// kHugeBlock bytes or more, and are glibc's malloc and friends otherwise. Where THP is off or
// unsupported the madvise fails and changes nothing. Measured (docs/benchmarks.md, "Decisions
// and what they rest on"): no change in S-Table 2's times beyond the machine's noise; the worst
// cancellation latency at 35k vertices 121 -> 74 ms, before the cancelled factorization's
// zeroing was skipped (kCancelPoint in sparse_cholesky.cpp).
constexpr size_t kHugeBlock = size_t{4} << 20;

void AdviseHugePages(void* p, size_t bytes) {
  if (p == nullptr || bytes < kHugeBlock) return;
  const uintptr_t page = 4096;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + page - 1) & ~(page - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(page - 1);
  if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

void* HugeMalloc(size_t bytes) {
  void* p = std::malloc(bytes);
  AdviseHugePages(p, bytes);
  return p;
}

void* HugeCalloc(size_t count, size_t size) {
  void* p = std::calloc(count, size);
  if (size != 0 && count <= SIZE_MAX / size) AdviseHugePages(p, count * size);
  return p;
}

void* HugeRealloc(void* old, size_t bytes) {
  void* p = std::realloc(old, bytes);
  AdviseHugePages(p, bytes);
  return p;
}

void InstallAllocator() {
  static const bool installed = [] {
    SuiteSparse_config.malloc_func = HugeMalloc;
    SuiteSparse_config.calloc_func = HugeCalloc;
    SuiteSparse_config.realloc_func = HugeRealloc;
    SuiteSparse_config.free_func = std::free;
    return true;
  }();
  (void)installed;
}

// The next definitions (LAPACK's and the BLAS's) of the routines this file defines, looked up
// once; a missing one is a broken installation, reported and fatal.
template <class Fn>
Fn NextDefinition(const char* name) {
  auto* next = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, name));
  if (next == nullptr) {
    std::fprintf(stderr, "inbetween: %s not found after this executable (%s)\n", name, dlerror());
    std::abort();
  }
  return next;
}

using DpotrfFn = void (*)(const char*, const int*, double*, const int*, int*, size_t);
using DsyrkFn = void (*)(const char*, const char*, const int*, const int*, const double*,
                         const double*, const int*, const double*, double*, const int*, size_t,
                         size_t);
using DgemmFn = void (*)(const char*, const char*, const int*, const int*, const int*,
                         const double*, const double*, const int*, const double*, const int*,
                         const double*, double*, const int*, size_t, size_t);
using DtrsmFn = void (*)(const char*, const char*, const char*, const char*, const int*, const int*,
                         const double*, const double*, const int*, double*, const int*, size_t,
                         size_t, size_t, size_t);

// Each Fn type above names one routine, so one cached lookup per type.
template <class Fn>
Fn Next(const char* name) {
  static const Fn f = NextDefinition<Fn>(name);
  return f;
}
DpotrfFn LapackPotrf() { return Next<DpotrfFn>("dpotrf_"); }
DsyrkFn BlasSyrk() { return Next<DsyrkFn>("dsyrk_"); }
DgemmFn BlasGemm() { return Next<DgemmFn>("dgemm_"); }
DtrsmFn BlasTrsm() { return Next<DtrsmFn>("dtrsm_"); }

// kDensePanel: the dense blocks of a supernodal factorization are factored and updated in panels
// of this many columns, with a poll between panels (kCancelPoint). The last supernodes of S-Table
// 2's 311k-vertex row are 2,492 columns wide: LAPACK's dpotrf_ on it took 118 ms and a dsyrk_ of
// 1,926 x 735 95 ms, single calls (measured with a temporary timer on every call).
// A panel of 256 columns bounds the work between polls to ~30 ms there. Blocks below
// kPanelFrom columns go to LAPACK/BLAS whole. The panelling depends on sizes only, never on
// whether a token is set, so results are the same with and without one.
constexpr int kDensePanel = SparseCholesky::kDensePanel;
constexpr int kPanelFrom = 2 * kDensePanel;

// Lower-triangular dense Cholesky of the n x n column-major block `a`, right-looking in panels of
// kDensePanel columns: factor the panel's diagonal block (LAPACK), solve the rows below it
// (dtrsm_), subtract their outer product from the trailing block (dsyrk_). Polls before every
// panel; cancelled: *info = 1 (see kCancelPoint). info > 0 otherwise names the first column whose
// pivot is not positive, as LAPACK's does.
void PanelledPotrf(int n, double* a, int lda, int* info) {
  const double one = 1.0, minus_one = -1.0;
  const auto at = [&](int row, int col) { return a + row + static_cast<size_t>(col) * lda; };
  for (int j = 0; j < n; j += kDensePanel) {
    if (internal::SupernodalFactorizationCancelled()) {
      internal::StopSupernodalFactorizationHere(info);
      return;
    }
    const int b = std::min(kDensePanel, n - j), rest = n - j - b;
    LapackPotrf()("L", &b, at(j, j), &lda, info, 1);
    if (*info != 0) {
      *info += j;
      return;
    }
    if (rest == 0) break;
    BlasTrsm()("R", "L", "T", "N", &rest, &b, &one, at(j, j), &lda, at(j + b, j), &lda, 1, 1, 1, 1);
    // Through this file's dsyrk_, which panels a large update again.
    dsyrk_("L", "N", &rest, &b, &minus_one, at(j + b, j), &lda, &one, at(j + b, j + b), &lda, 1, 1);
  }
  *info = 0;
}

// OpenBLAS's pthread build (what scripts/setup installs) would split each BLAS call over every
// core, on top of our own threads, and its sums would then depend on the machine's core count: it
// is pinned to one thread (openblas_set_num_threads, looked up at run time because the programs
// link the generic libblas), so results are bit-identical for any thread count of ours and on any
// machine. Pinned while the process loads, not at the first supernodal factorization: pinned late,
// in a child forked from a process that had not factored and whose address space was then capped
// (RLIMIT_AS), OpenBLAS 0.3.21's first factorization of a 10k- or 22k-unknown matrix spun in
// blas_memory_alloc, retrying a 128 MiB mmap forever (0.3.30 exits instead), where it should have
// answered RESOURCE_EXHAUSTED or factored: seen in MapToBoundaryTest.OutOfMemory* and
// SparseCholeskyTest.FirstSupernodalFactorizationUnder... Pinned at load, neither hangs.
void PinBlasToOneThread() {
  using SetThreads = void (*)(int);
  auto* set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  if (set != nullptr) set(1);
}

const bool kSetUpAtLoad = [] {
  PinBlasToOneThread();
  InstallAllocator();
  return true;
}();

}  // namespace
}  // namespace inbetween::solver

extern "C" void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info,
                        size_t uplo_length) {
  namespace sv = inbetween::solver;
  if (sv::internal::SupernodalFactorizationCancelled()) {
    sv::internal::StopSupernodalFactorizationHere(info);
    return;
  }
  if (*n >= sv::kPanelFrom && (*uplo == 'L' || *uplo == 'l')) {
    sv::PanelledPotrf(*n, a, *lda, info);
    return;
  }
  sv::LapackPotrf()(uplo, n, a, lda, info, uplo_length);
}

// C = alpha A A^T + beta C (lower, A not transposed: CHOLMOD's update of an ancestor) in column
// panels of kDensePanel: each panel's diagonal block (dsyrk_) and the rows below it (dgemm_), a
// poll before each; every entry of C is still one call's sum over all of A's columns. Other forms
// and small blocks go to the BLAS whole. Skipped once the factorization is cancelled.
extern "C" void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k,
                       const double* alpha, const double* a, const int* lda, const double* beta,
                       double* c, const int* ldc, size_t uplo_length, size_t trans_length) {
  namespace sv = inbetween::solver;
  if (sv::internal::SupernodalFactorizationCancelled()) return;
  const bool lower_n = (*uplo == 'L' || *uplo == 'l') && (*trans == 'N' || *trans == 'n');
  if (!lower_n || *n < sv::kPanelFrom) {
    sv::BlasSyrk()(uplo, trans, n, k, alpha, a, lda, beta, c, ldc, uplo_length, trans_length);
    return;
  }
  for (int j = 0; j < *n; j += sv::kDensePanel) {
    if (j > 0 && sv::internal::SupernodalFactorizationCancelled()) return;
    const int b = std::min(sv::kDensePanel, *n - j), rest = *n - j - b;
    double* cj = c + j + static_cast<size_t>(j) * *ldc;
    sv::BlasSyrk()("L", "N", &b, k, alpha, a + j, lda, beta, cj, ldc, 1, 1);
    if (rest > 0) {
      sv::BlasGemm()("N", "T", &rest, &b, k, alpha, a + j + b, lda, a + j, lda, beta, cj + b, ldc,
                     1, 1);
    }
  }
}

// CHOLMOD's other BLAS-3 calls in a supernodal factorization: passed through, skipped once the
// factorization is cancelled (their largest took under 10 ms at 311k vertices).
extern "C" void dgemm_(const char* transa, const char* transb, const int* m, const int* n,
                       const int* k, const double* alpha, const double* a, const int* lda,
                       const double* b, const int* ldb, const double* beta, double* c,
                       const int* ldc, size_t transa_length, size_t transb_length) {
  namespace sv = inbetween::solver;
  if (sv::internal::SupernodalFactorizationCancelled()) return;
  sv::BlasGemm()(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc, transa_length,
                 transb_length);
}

extern "C" void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag,
                       const int* m, const int* n, const double* alpha, const double* a,
                       const int* lda, double* b, const int* ldb, size_t side_length,
                       size_t uplo_length, size_t transa_length, size_t diag_length) {
  namespace sv = inbetween::solver;
  if (sv::internal::SupernodalFactorizationCancelled()) return;
  sv::BlasTrsm()(side, uplo, transa, diag, m, n, alpha, a, lda, b, ldb, side_length, uplo_length,
                 transa_length, diag_length);
}

// CHOLMOD's OpenMP regions run on the calling thread. Debian's CHOLMOD (SuiteSparse 5.12, built
// with OpenMP) opens parallel regions inside the supernodal factorization, per supernode (copying A
// into it, clearing and scattering), each with a fixed team of 4 threads (the compiled call passes
// 3 * test + 1 as the team size, the test being the region's size condition, so OMP_NUM_THREADS
// does not change it). On a 2-core machine where our own threads already factor the two shapes of a
// comesh concurrently, those teams oversubscribe the cores, and even a team of one costs a futex
// system call per region (libgomp's barrier): measured on S-Table 2's 35k row (docs/benchmarks.md,
// "Decisions and what they rest on"). The executable defines GOMP_parallel, the libgomp entry point
// gcc compiles `#pragma omp parallel` to (the dynamic linker binds CHOLMOD's calls to this
// definition, as for dpotrf_ above), and runs the region's body once on the calling thread, as
// libgomp does for a team of one: outside any team, omp_get_num_threads() is 1 and
// omp_get_thread_num() 0, so the body's worksharing loops (static schedules: CHOLMOD imports no
// other libgomp entry point) cover every iteration, in order. CHOLMOD is the only library here that
// uses OpenMP (our own code is not built with it); its regions only move data, so the factor is the
// same.
extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned /*num_threads*/,
                              unsigned /*flags*/) {
  fn(data);
}
