// Small hand-built multimeshes for the inbetweening tests (no dependency on mesh building).
#pragma once

#include <cmath>
#include <vector>

#include "solver/core/types.h"
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

inline double SignedArea(const Points& x, const Triangle& t) {
  const Point e1 = x[t[1]] - x[t[0]];
  const Point e2 = x[t[2]] - x[t[0]];
  return 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
}

inline double MaxDistance(const Points& a, const Points& b) {
  double d = 0.0;
  for (size_t v = 0; v < a.size(); ++v) d = std::max(d, (a[v] - b[v]).norm());
  return d;
}

}  // namespace inbetween::solver::interp_test
