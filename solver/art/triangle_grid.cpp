// Uniform grid over triangles (see triangle_grid.h).
#include "solver/art/triangle_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

// Segment pq meets the closed box (slab test).
bool SegmentMeetsBox(const Point& p, const Point& q, const Eigen::AlignedBox2d& box) {
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 2; ++k) {
    const double d = q[k] - p[k];
    if (d == 0.0) {
      if (p[k] < box.min()[k] || p[k] > box.max()[k]) return false;
      continue;
    }
    double ta = (box.min()[k] - p[k]) / d, tb = (box.max()[k] - p[k]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

Eigen::Vector3d Barycentric(const Point& a, const Point& b, const Point& c, const Point& p) {
  const double d = Cross(b - a, c - a);
  const double l1 = Cross(p - a, c - a) / d;
  const double l2 = Cross(b - a, p - a) / d;
  return {1.0 - l1 - l2, l1, l2};
}

double DistanceToTriangle(const Point& a, const Point& b, const Point& c, const Point& p) {
  if (Barycentric(a, b, c, p).minCoeff() >= 0.0) return 0.0;
  return std::min(
      {DistanceToSegment(p, a, b), DistanceToSegment(p, b, c), DistanceToSegment(p, c, a)});
}

TriangleGrid::TriangleGrid(const std::vector<Triangle>& triangles, const Points& vertices,
                           double triangles_per_cell)
    : triangles_(triangles), vertices_(vertices) {
  for (const Triangle& t : triangles) {
    for (int v : t) bounds_.extend(vertices[v]);
  }
  if (bounds_.isEmpty()) {
    cells_.resize(1);
    return;
  }
  const Point size = bounds_.sizes();
  const double cells = std::max(1.0, triangles.size() / std::max(triangles_per_cell, 1e-3));
  cell_size_ = std::sqrt(size.x() * size.y() / cells);
  // A flat box (all vertices on a line) still gets `cells` cells along its length.
  if (!(cell_size_ > 0.0)) cell_size_ = std::max(size.maxCoeff() / cells, 1e-300);
  // Bound the grid's memory for very thin boxes: at most a few cells per triangle in all.
  const double max_side = 4.0 * cells + 1.0;
  cell_size_ = std::max({cell_size_, size.x() / max_side, size.y() / max_side});
  nx_ = std::max(1, static_cast<int>(std::ceil(size.x() / cell_size_)));
  ny_ = std::max(1, static_cast<int>(std::ceil(size.y() / cell_size_)));
  cells_.resize(static_cast<size_t>(nx_) * ny_);
  for (size_t t = 0; t < triangles.size(); ++t) {
    const Point& a = vertices[triangles[t][0]];
    const Point& b = vertices[triangles[t][1]];
    const Point& c = vertices[triangles[t][2]];
    if (!(SignedArea2(a, b, c) > 0.0)) continue;
    Box box(a);
    box.extend(b).extend(c);
    const Eigen::Vector2i lo = CellOf(box.min()), hi = CellOf(box.max());
    for (int j = lo.y(); j <= hi.y(); ++j) {
      for (int i = lo.x(); i <= hi.x(); ++i) cells_[j * nx_ + i].push_back(static_cast<int>(t));
    }
    ++indexed_;
  }
}

Eigen::Vector2i TriangleGrid::CellOf(const Point& p) const {
  const Point r = (p - bounds_.min()) / cell_size_;
  auto clamp = [](double x, int n) {
    return x <= 0.0 ? 0 : x >= n - 1 ? n - 1 : static_cast<int>(std::floor(x));
  };
  return {clamp(r.x(), nx_), clamp(r.y(), ny_)};
}

TriangleGrid::Box TriangleGrid::CellBox(int i, int j) const {
  const Point lo = bounds_.min() + cell_size_ * Point(i, j);
  return Box(lo, lo + Point(cell_size_, cell_size_));
}

int TriangleGrid::Containing(const Point& p, double tolerance) const {
  if (empty()) return -1;
  const Eigen::Vector2i c = CellOf(p);
  int best = -1;
  double depth = -tolerance;
  for (int t : Cell(c.x(), c.y())) {
    const Triangle& tri = triangles_[t];
    const double d =
        Barycentric(vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]], p).minCoeff();
    if (d > depth || (d == depth && best < 0)) best = t, depth = d;
  }
  return best;
}

int TriangleGrid::Nearest(const Point& p, double* distance) const {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  if (empty()) return -1;
  const Eigen::Vector2i c = CellOf(p);
  for (int r = 0;; ++r) {
    for (int j = c.y() - r; j <= c.y() + r; ++j) {
      if (j < 0 || j >= ny_) continue;
      const int step = (j == c.y() - r || j == c.y() + r) ? 1 : 2 * r;  // the ring only
      for (int i = c.x() - r; i <= c.x() + r; i += std::max(step, 1)) {
        if (i < 0 || i >= nx_) continue;
        for (int t : Cell(i, j)) {
          const Triangle& tri = triangles_[t];
          const double d =
              DistanceToTriangle(vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]], p);
          if (d < best_d || (d == best_d && t < best)) best = t, best_d = d;
        }
      }
    }
    // Every unvisited cell lies beyond a side of the visited block that is inside the grid, so
    // the distance to the nearest such side's line bounds every unvisited triangle's distance.
    const Point lo = bounds_.min() + cell_size_ * Point(c.x() - r, c.y() - r);
    const Point hi = lo + cell_size_ * Point(2 * r + 1, 2 * r + 1);
    double bound = std::numeric_limits<double>::infinity();
    if (c.x() - r > 0) bound = std::min(bound, std::max(0.0, p.x() - lo.x()));
    if (c.y() - r > 0) bound = std::min(bound, std::max(0.0, p.y() - lo.y()));
    if (c.x() + r + 1 < nx_) bound = std::min(bound, std::max(0.0, hi.x() - p.x()));
    if (c.y() + r + 1 < ny_) bound = std::min(bound, std::max(0.0, hi.y() - p.y()));
    if (std::isinf(bound) || best_d < bound) break;
  }
  if (distance != nullptr) *distance = best_d;
  return best;
}

std::vector<int> TriangleGrid::AlongSegment(const Point& p, const Point& q) const {
  std::vector<int> out;
  if (empty()) return out;
  const Eigen::Vector2i lo = CellOf(p.cwiseMin(q)), hi = CellOf(p.cwiseMax(q));
  const double margin = 1e-9 * cell_size_;
  for (int j = lo.y(); j <= hi.y(); ++j) {
    for (int i = lo.x(); i <= hi.x(); ++i) {
      Box box = CellBox(i, j);
      box.min().array() -= margin;
      box.max().array() += margin;
      if (!SegmentMeetsBox(p, q, box)) continue;
      const std::vector<int>& cell = Cell(i, j);
      out.insert(out.end(), cell.begin(), cell.end());
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace inbetween::solver
