// The comesh line search's inversion bound (see comesh_step_bound.h).
#include "solver/comesh/comesh_step_bound.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/core/parallel_chunks.h"

namespace inbetween::solver {

double MaxNonInvertingStep(const std::vector<Triangle>& triangles,
                           const std::vector<Points>& shapes, const std::vector<Points>& disp,
                           int threads) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr int kChunk = 4096;
  const int num_triangles = static_cast<int>(triangles.size());
  std::vector<double> part(NumChunks(num_triangles, kChunk), kInf);
  ParallelChunks(num_triangles, kChunk, threads, [&](int chunk, int begin, int end) {
    double best = kInf;
    for (size_t s = 0; s < shapes.size(); ++s) {
      const Points& x = shapes[s];
      const Points& dx = disp[s];
      for (int ti = begin; ti < end; ++ti) {
        const auto [c0, c1, c2] = AreaAlong(x, dx, triangles[ti]);  // c0 > 0
        double root = kInf;
        if (std::abs(c2) <= 1e-14 * (std::abs(c1) + std::abs(c0))) {
          if (c1 < 0.0) root = -c0 / c1;
        } else {
          // The smallest positive root of c2 s^2 + c1 s + c0, in the cancellation-free form.
          const double disc = c1 * c1 - 4.0 * c2 * c0;
          if (disc >= 0.0) {
            const double sq = std::sqrt(disc);
            const double qq = -0.5 * (c1 + (c1 >= 0.0 ? sq : -sq));
            const double r1 = qq / c2;
            const double r2 = (qq != 0.0) ? c0 / qq : kInf;
            if (r1 > 0.0) root = std::min(root, r1);
            if (r2 > 0.0) root = std::min(root, r2);
          }
        }
        best = std::min(best, root);
      }
    }
    part[chunk] = best;
  });
  double best = kInf;
  for (double b : part) best = std::min(best, b);
  return best;
}

}  // namespace inbetween::solver
