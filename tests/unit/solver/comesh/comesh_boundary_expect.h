// gtest check shared by the comesh topology and optimizer tests: a multimesh's boundary after
// topology passes (and inner runs) is still the same point set in every shape.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "solver/comesh/comesh_topology.h"
#include "solver/core/types.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver::testing {

// The loops of m (Multimesh::boundary as one loop when boundary_loops is empty).
inline std::vector<std::vector<int>> LoopsOf(const Multimesh& m) {
  return m.boundary_loops.empty() ? std::vector<std::vector<int>>{m.boundary} : m.boundary_loops;
}

using ::inbetween::solver::DistanceToSegment;  // callers name it testing::DistanceToSegment

// `after` came from `before` by topology passes (boundary collapses drop vertices that lie on a
// straight stretch in every shape) and inner runs (sliders move along their stretch). Checks, per
// loop and shape: every vertex of `after`'s loop lies on `before`'s loop polyline; every vertex of
// `before` that is a corner in a shape (not strictly inside its neighbours' segment there) is
// still on the loop, in the same place in that shape; the loop count is the same. With
// corner_degrees >= 0 (the optimizer's outline sliding, ComeshOptions::outline_corner_degrees),
// only the vertices whose turn exceeds it count as corners: the others may slide along the loop.
inline void ExpectBoundaryKept(const Multimesh& before, const Multimesh& after,
                               double corner_degrees = -1.0) {
  const auto old_loops = LoopsOf(before), new_loops = LoopsOf(after);
  ASSERT_EQ(old_loops.size(), new_loops.size());
  ASSERT_EQ(before.num_shapes(), after.num_shapes());
  for (size_t l = 0; l < old_loops.size(); ++l) {
    const std::vector<int>& old_loop = old_loops[l];
    const std::vector<int>& new_loop = new_loops[l];
    const size_t n = old_loop.size();
    ASSERT_GE(new_loop.size(), 3u);
    for (int s = 0; s < before.num_shapes(); ++s) {
      const Points& x = before.shapes[s];
      const Points& y = after.shapes[s];
      double diag = 0.0;
      for (int v : old_loop) diag = std::max(diag, (x[v] - x[old_loop[0]]).norm());
      for (int v : new_loop) {
        double d = std::numeric_limits<double>::infinity();
        for (size_t k = 0; k < n; ++k) {
          d = std::min(d, DistanceToSegment(y[v], x[old_loop[k]], x[old_loop[(k + 1) % n]]));
        }
        EXPECT_LE(d, 1e-9 * diag) << "loop " << l << " shape " << s << " vertex " << v;
      }
    }
    // Corners are pinned in their own shape (a vertex may be a corner in one shape and slide in
    // another), so each shape's corners are looked up in that shape.
    for (int s = 0; s < before.num_shapes(); ++s) {
      const Points& x = before.shapes[s];
      for (size_t k = 0; k < n; ++k) {
        const int v = old_loop[k], p = old_loop[(k + n - 1) % n], q = old_loop[(k + 1) % n];
        if (StrictlyInsideSegment(x[p], x[q], x[v])) continue;
        if (corner_degrees >= 0.0) {
          const Point in = x[v] - x[p], out = x[q] - x[v];
          const double turn = std::acos(std::clamp(in.dot(out) / (in.norm() * out.norm()), -1.0,
                                                   1.0)) * 180.0 / std::numbers::pi;
          if (turn <= corner_degrees) continue;
        }
        bool found = false;
        for (int u : new_loop) found |= after.shapes[s][u] == x[v];
        EXPECT_TRUE(found) << "corner " << v << " of loop " << l << " in shape " << s << " lost";
      }
    }
  }
}

}  // namespace inbetween::solver::testing
