// Keeping freed memory in the process (glibc malloc), for programs that run the solver.
//
// The comesh optimizer frees and reallocates the same large blocks over and over: vectors of all
// unknowns every iteration, a CHOLMOD factor every inner run. glibc's defaults hand such blocks
// back to the kernel as soon as they are freed (blocks above a threshold that starts at 128 KiB
// are mmap'd and unmapped; the heap top is trimmed above 128 KiB), so every reuse is a fresh run
// of page faults, and on virtual machines each unmap or trim also costs a TLB shootdown across
// cores. Measured on the S-Table 2 rows of
// `comesh-scaling` (2-core VM, docs/benchmarks.md): the rows from 278 to 35k vertices took 1.2 to
// 1.8 times as long with the defaults.
//
// RetainFreedMemory() sets M_MMAP_THRESHOLD to 32 MiB (glibc's largest), M_TRIM_THRESHOLD to
// 256 MiB and M_TOP_PAD to 64 MiB: freed blocks stay in the heap and are reused. The process's
// resident size then stays near its peak instead of falling back after a job; that is why the
// CLI and the benchmarks call it and the multi-tenant server only with --retain-freed-memory (its
// per-thread arenas would each keep their own peak; docs/hardening.md "Resource bounds").
// Results do not change.
// Call it once, at the start of main. No-op where the C library is not glibc.
#pragma once

namespace inbetween::solver {

void RetainFreedMemory();

}  // namespace inbetween::solver
