// BCQN curing of a comesh search direction (see comesh_cure.h).
#include "solver/comesh/comesh_cure.h"

#include <algorithm>

#include "solver/comesh/comesh_step_bound.h"
#include "solver/core/parallel_chunks.h"

namespace inbetween::solver {

int CureDirection(const std::vector<Triangle>& triangles, const std::vector<Points>& shapes,
                  const ComeshLayout& layout, double cure_keep, int threads,
                  const CancelToken* cancel, std::vector<Points>* disp, Eigen::VectorXd* d) {
  constexpr int kChunk = 4096;
  layout.Displacements(*d, disp);
  if (Cancelled(cancel)) return -1;
  // Per triangle and shape, the factor its moving corners need (1: none), in parallel; then each
  // vertex takes the smallest of its triangles' factors (serial, in triangle order).
  const int num_triangles = static_cast<int>(triangles.size());
  const int num_shapes = layout.num_shapes();
  std::vector<double> need(static_cast<size_t>(num_triangles) * num_shapes, 1.0);
  ParallelChunks(num_triangles, kChunk, threads, [&](int, int begin, int end) {
    if (Cancelled(cancel)) return;  // `need` partly filled: not used
    for (int s = 0; s < num_shapes; ++s) {
      const Points& x = shapes[s];
      const Points& dx = (*disp)[s];
      for (int ti = begin; ti < end; ++ti) {
        const auto [c0, c1, c2] = AreaAlong(x, dx, triangles[ti]);
        if (!(c0 + c1 < cure_keep * c0)) continue;
        need[static_cast<size_t>(s) * num_triangles + ti] = (1.0 - cure_keep) * c0 / (-c1);
      }
    }
  });
  if (Cancelled(cancel)) return -1;
  std::vector<double> factor(layout.vars().size(), 1.0);
  for (int s = 0; s < num_shapes; ++s) {
    for (int ti = 0; ti < num_triangles; ++ti) {
      if (ti % (16 * kChunk) == 0 && Cancelled(cancel)) return -1;
      const double c = need[static_cast<size_t>(s) * num_triangles + ti];
      if (c >= 1.0) continue;
      for (int k = 0; k < 3; ++k) {
        const int i = layout.index(s, triangles[ti][k]);
        if (i >= 0) factor[i] = std::min(factor[i], c);
      }
    }
  }
  int cured = 0;
  for (size_t i = 0; i < factor.size(); ++i) {
    if (factor[i] >= 1.0) continue;
    const ComeshLayout::Var& var = layout.vars()[i];
    const int m = var.slider ? 1 : 2;
    d->segment(var.offset, m) *= factor[i];
    cured += m;
  }
  return cured;
}

}  // namespace inbetween::solver
