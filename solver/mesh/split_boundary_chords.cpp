// Splits interior edges with boundary ends at their midpoints (1 -> 2 triangles on each side), e.g.
// every one joining two boundary vertices, so that no triangle is spanned by them alone.
#include "solver/mesh/split_boundary_chords.h"

#include <algorithm>
#include <map>
#include <utility>

namespace inbetween::solver {

int SplitInteriorEdges(const std::vector<Points*>& shapes, std::vector<Triangle>* triangles,
                       std::vector<bool>* is_boundary, int min_boundary_ends) {
  using Edge = std::pair<int, int>;
  auto key = [](int a, int b) { return Edge(std::min(a, b), std::max(a, b)); };
  std::map<Edge, int> count;
  for (const Triangle& t : *triangles) {
    for (int k = 0; k < 3; ++k) ++count[key(t[k], t[(k + 1) % 3])];
  }
  // The edges in a deterministic (sorted) order, each with its new midpoint vertex.
  std::map<Edge, int> midpoint;
  for (const auto& [edge, c] : count) {
    if (c == 2 && (*is_boundary)[edge.first] + (*is_boundary)[edge.second] >= min_boundary_ends) {
      midpoint[edge] = static_cast<int>(is_boundary->size());
      for (Points* x : shapes) x->push_back(0.5 * ((*x)[edge.first] + (*x)[edge.second]));
      is_boundary->push_back(false);
    }
  }
  if (midpoint.empty()) return 0;
  // Split triangles; a triangle may hold several such edges, so repeat until none is left.
  std::vector<Triangle> pending = std::move(*triangles);
  triangles->clear();
  while (!pending.empty()) {
    std::vector<Triangle> next;
    for (const Triangle& t : pending) {
      bool split = false;
      for (int k = 0; k < 3 && !split; ++k) {
        const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        auto it = midpoint.find(key(a, b));
        if (it == midpoint.end()) continue;
        next.push_back({a, it->second, c});
        next.push_back({it->second, b, c});
        split = true;
      }
      if (!split) triangles->push_back(t);
    }
    pending = std::move(next);
  }
  return static_cast<int>(midpoint.size());
}

int SplitBoundaryChords(Points* vertices, std::vector<Triangle>* triangles,
                        std::vector<bool>* is_boundary) {
  return SplitInteriorEdges({vertices}, triangles, is_boundary, 2);
}

}  // namespace inbetween::solver
