// A deterministic parallel-for over fixed-size chunks (std::thread, no pool), shared by the
// comesh and inbetweening stages.
//
// Work [0, n) is cut into chunks of a fixed size that does NOT depend on the thread count, and
// chunk c always runs on thread c % threads. Callers write per-chunk results into per-chunk slots
// and reduce them afterwards in chunk order, so every result is bit-identical for any number of
// threads (including 1). Threads are started per call: only worth it for large meshes, hence
// the `min_parallel` cut-off below which the call stays on the caller's thread.
#pragma once

#include <algorithm>
#include <thread>
#include <vector>

namespace inbetween::solver {

// Resolves an options value: <= 0 means std::thread::hardware_concurrency() (at least 1).
inline int ResolveThreads(int threads) {
  if (threads > 0) return threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

inline int NumChunks(int n, int chunk_size) { return (n + chunk_size - 1) / chunk_size; }

// Calls f(chunk, begin, end) for every chunk of [0, n). f must only write chunk-private data.
template <typename F>
void ParallelChunks(int n, int chunk_size, int threads, F&& f, int min_parallel = 1 << 13) {
  const int chunks = NumChunks(n, chunk_size);
  const int workers = std::min(std::max(1, threads), chunks);
  auto run = [&](int worker) {
    for (int c = worker; c < chunks; c += workers) {
      f(c, c * chunk_size, std::min(n, (c + 1) * chunk_size));
    }
  };
  if (workers <= 1 || n < min_parallel) {
    for (int c = 0; c < chunks; ++c) f(c, c * chunk_size, std::min(n, (c + 1) * chunk_size));
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  for (int w = 1; w < workers; ++w) pool.emplace_back(run, w);
  run(0);
  for (std::thread& t : pool) t.join();
}

}  // namespace inbetween::solver
