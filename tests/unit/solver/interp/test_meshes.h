// Small hand-built multimeshes for the inbetweening tests (no dependency on mesh building).
#pragma once

#include <cmath>
#include <vector>

#include "solver/core/types.h"
#include "solver/geometry/primitives.h"
#include "solver/interp/polar.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver::interp_test {

// A grid of nx x ny cells on [0, nx*h] x [0, ny*h], two positive triangles per cell.
inline Multimesh GridMesh(int nx, int ny, double h = 1.0) {
  Multimesh mesh;
  Points points;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) points.emplace_back(i * h, j * h);
  }
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  mesh.shapes.push_back(points);
  return mesh;
}

inline Points Rotated(const Points& points, double angle, const Point& center) {
  const Eigen::Matrix2d r = RotationMatrix(angle);
  Points out;
  for (const Point& p : points) out.push_back(center + r * (p - center));
  return out;
}

inline Points Translated(const Points& points, const Point& offset) {
  Points out;
  for (const Point& p : points) out.push_back(p + offset);
  return out;
}

// Bends a strip along x (length `length`, 0 <= y < length / angle) into an arc of `angle`
// radians; orientation-preserving.
inline Points Bent(const Points& points, double length, double angle) {
  const double r = length / angle;
  Points out;
  for (const Point& p : points) {
    const double a = p.x() / r;
    out.emplace_back((r - p.y()) * std::sin(a), r - (r - p.y()) * std::cos(a));
  }
  return out;
}

inline double SignedArea(const Points& x, const Triangle& t) { return 0.5 * SignedArea2(t, x); }

inline double MaxDistance(const Points& a, const Points& b) {
  double d = 0.0;
  for (size_t v = 0; v < a.size(); ++v) d = std::max(d, (a[v] - b[v]).norm());
  return d;
}

// Bends a strip of width 1 (0 <= y <= 1) about its centre line y = 1/2 into an arc of `angle`
// radians; keeps the total area.
inline Points BentAboutCentre(const Points& points, double length, double angle) {
  return Bent(Translated(points, Point(0, -0.5)), length, angle);
}

inline double TotalArea(const Points& x, const std::vector<Triangle>& triangles) {
  double a = 0.0;
  for (const Triangle& t : triangles) a += SignedArea(x, t);
  return a;
}

// A grid (nx x ny cells of size h) with a vertical slit at column nx/2 from the bottom up to row
// `slit_rows`: the slit's vertices (but its top end) are duplicated for the cells on its right,
// and each slit segment is a cohesive pair {left a, left b, right c, right d}.
// If `open` != 0 a second shape opens the slit like a mouth (normal jump `open` at the bottom),
// and if `shear` != 0 a third shape slides the two sides along the slit instead.
inline Multimesh SlitMesh(int nx, int ny, int slit_rows, double h, double open, double shear) {
  Multimesh mesh = GridMesh(nx, ny, h);
  const int i0 = nx / 2;
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  std::vector<int> dup(ny + 1, -1);
  for (int j = 0; j < slit_rows; ++j) {
    dup[j] = static_cast<int>(mesh.shapes[0].size());
    mesh.shapes[0].push_back(mesh.shapes[0][id(i0, j)]);
  }
  // Cells right of the slit: triangles 2 (j nx + i) and 2 (j nx + i) + 1.
  for (int j = 0; j < slit_rows; ++j) {
    for (int k = 0; k < 2; ++k) {
      Triangle& t = mesh.triangles[2 * (j * nx + i0) + k];
      for (int& v : t) {
        for (int jj = 0; jj < slit_rows; ++jj) {
          if (v == id(i0, jj)) v = dup[jj];
        }
      }
    }
  }
  for (int j = 0; j < slit_rows; ++j) {
    mesh.cohesive_edges.push_back(
        {id(i0, j), id(i0, j + 1), dup[j], j + 1 < slit_rows ? dup[j + 1] : id(i0, j + 1)});
  }
  std::vector<int> side(mesh.shapes[0].size(), 0);
  for (size_t v = 0; v < side.size(); ++v) {
    const Point& p = mesh.shapes[0][v];
    side[v] = p.x() < i0 * h - 1e-12 ? -1 : p.x() > i0 * h + 1e-12 ? 1 : -1;
  }
  for (int j = 0; j < slit_rows; ++j) side[dup[j]] = 1;
  const double ys = slit_rows * h, width = 0.5 * nx * h;
  for (double amount : {open, shear}) {
    if (amount == 0.0) continue;
    Points moved;
    for (size_t v = 0; v < side.size(); ++v) {
      const Point& p = mesh.shapes[0][v];
      const double phi = std::max(0.0, 1.0 - p.y() / ys);
      const double psi = std::max(0.0, 1.0 - std::abs(p.x() - i0 * h) / width);
      const double d = amount * side[v] * phi * psi;
      moved.push_back(amount == open ? Point(p.x() + d, p.y()) : Point(p.x(), p.y() + d));
    }
    mesh.shapes.push_back(moved);
  }
  return mesh;
}

}  // namespace inbetween::solver::interp_test
