// Hilbert-curve vertex numbering (see vertex_order.h).
#include "solver/mesh/vertex_order.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>

namespace inbetween::solver {
namespace {

constexpr int kOrder = 16;  // 2^16 cells per side

// Index of cell (x, y) on the Hilbert curve filling a 2^kOrder square (the classic rotate-and-
// flip walk from the top level down).
uint64_t HilbertIndex(uint32_t x, uint32_t y) {
  constexpr uint32_t side = 1u << kOrder;
  uint64_t d = 0;
  for (uint32_t s = side / 2; s > 0; s /= 2) {
    const uint32_t rx = (x & s) != 0 ? 1 : 0;
    const uint32_t ry = (y & s) != 0 ? 1 : 0;
    d += static_cast<uint64_t>(s) * s * ((3 * rx) ^ ry);
    if (ry == 0) {
      if (rx == 1) {
        x = side - 1 - x;
        y = side - 1 - y;
      }
      std::swap(x, y);
    }
  }
  return d;
}

}  // namespace

std::vector<int> HilbertOrder(const Points& points) {
  const int n = static_cast<int>(points.size());
  std::vector<int> to(n);
  if (n == 0) return to;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Point lo(kInf, kInf), hi(-kInf, -kInf);  // over the finite points (none: every cell is 0)
  for (const Point& p : points) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double top = static_cast<double>((1u << kOrder) - 1);
  auto cell = [&](double v, double a, double b) -> uint32_t {
    if (!(b > a) || !(v > a)) return 0;  // a flat box, NaN, or the low edge
    return static_cast<uint32_t>(std::min(top, (v - a) / (b - a) * top));
  };
  std::vector<std::pair<uint64_t, int>> key(n);
  for (int v = 0; v < n; ++v) {
    key[v] = {
        HilbertIndex(cell(points[v].x(), lo.x(), hi.x()), cell(points[v].y(), lo.y(), hi.y())), v};
  }
  std::sort(key.begin(), key.end());
  for (int k = 0; k < n; ++k) to[key[k].second] = k;
  return to;
}

void RenumberSpatially(Multimesh* mesh) {
  if (mesh->shapes.empty()) return;
  const int n = mesh->num_vertices();
  const std::vector<int> to = HilbertOrder(mesh->shapes[0]);
  for (Points& shape : mesh->shapes) {
    Points moved(n);
    for (int v = 0; v < n; ++v) moved[to[v]] = shape[v];
    shape = std::move(moved);
  }
  for (Triangle& t : mesh->triangles) {
    for (int& v : t) v = to[v];
  }
  std::stable_sort(mesh->triangles.begin(), mesh->triangles.end(),
                   [](const Triangle& a, const Triangle& b) {
                     return std::min({a[0], a[1], a[2]}) < std::min({b[0], b[1], b[2]});
                   });
  for (int& v : mesh->boundary) v = to[v];
  for (std::vector<int>& loop : mesh->boundary_loops) {
    for (int& v : loop) v = to[v];
  }
  for (std::array<int, 4>& c : mesh->cohesive_edges) {
    for (int& v : c) v = to[v];
  }
  for (int& v : mesh->pinned) v = to[v];
  std::sort(mesh->pinned.begin(), mesh->pinned.end());
}

}  // namespace inbetween::solver
