// A vertex's star in a triangle soup whose per-vertex triangle lists are kept by the caller
// (comesh topology editing, overlay coarsening).
#pragma once

#include <algorithm>
#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// The vertices that share a triangle with v, ascending, each once; `star` lists v's triangles
// (indices into `triangles`).
inline std::vector<int> StarNeighbours(const std::vector<Triangle>& triangles,
                                       const std::vector<int>& star, int v) {
  std::vector<int> out;
  for (int t : star) {
    for (int x : triangles[t]) {
      if (x != v) out.push_back(x);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace inbetween::solver
