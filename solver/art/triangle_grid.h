// A uniform grid over the triangles of one geometry: point location (the containing triangle, or
// the nearest one) and the triangles a segment may cross. Used by the art embedding
// (art_embedding.h) to put thousands of art points on a mesh of thousands of triangles in about
// O(1) per point and O(cells crossed) per segment.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// Barycentric coordinates of p in triangle (a, b, c): p = l0 a + l1 b + l2 c, l0 + l1 + l2 = 1,
// extended affinely outside the triangle. Requires a non-degenerate triangle.
Eigen::Vector3d Barycentric(const Point& a, const Point& b, const Point& c, const Point& p);

// Distance from p to the closed triangle (a, b, c) (0 inside).
double DistanceToTriangle(const Point& a, const Point& b, const Point& c, const Point& p);

class TriangleGrid {
 public:
  // `triangles_per_cell` sets the resolution: about triangles.size() / triangles_per_cell cells
  // over the vertices' bounding box, square cells. Triangles with non-positive area (none in a
  // valid multimesh) are left out: they have no barycentric coordinates. Keeps references to
  // `triangles` and `vertices`, which must outlive the grid.
  TriangleGrid(const std::vector<Triangle>& triangles, const Points& vertices,
               double triangles_per_cell = 2.0);

  // The triangle containing p (every barycentric coordinate >= -tolerance); among several, the
  // one p is deepest in (largest smallest coordinate), ties to the lower index. -1 if none.
  int Containing(const Point& p, double tolerance) const;

  // The triangle nearest to p (Euclidean distance to the closed triangle), ties to the lower
  // index; *distance (if given) receives it. Exact: rings of cells are searched outward until no
  // unvisited cell can hold a nearer triangle. -1 only without any triangle.
  int Nearest(const Point& p, double* distance = nullptr) const;

  // Indices of triangles whose bounding box may meet segment pq (a superset of those it
  // crosses), ascending.
  std::vector<int> AlongSegment(const Point& p, const Point& q) const;

  bool empty() const { return indexed_ == 0; }

 private:
  using Box = Eigen::AlignedBox2d;
  // Cell coordinates of p, clamped to the grid.
  Eigen::Vector2i CellOf(const Point& p) const;
  Box CellBox(int i, int j) const;
  const std::vector<int>& Cell(int i, int j) const { return cells_[j * nx_ + i]; }

  const std::vector<Triangle>& triangles_;
  const Points& vertices_;
  Box bounds_;
  double cell_size_ = 1.0;
  int nx_ = 1, ny_ = 1;
  int indexed_ = 0;
  std::vector<std::vector<int>> cells_;  // triangle indices per cell, ascending
};

}  // namespace inbetween::solver
