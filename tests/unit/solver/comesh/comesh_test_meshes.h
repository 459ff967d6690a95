// Test meshes for the comesh tests and the comesh benchmarks (header only, built in place so the
// tests do not depend on the mesh-building stage): a triangulated unit-square grid, its Tutte
// (uniform harmonic) embedding onto a regular hexagon, and smooth interior distortions.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "solver/core/types.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver::testing {

// (k+1)^2 vertices on [0,1]^2, 2 k^2 triangles of positive signed area, diagonals alternating
// so the mesh is symmetric; boundary listed counter-clockwise (positive orientation) from (0,0).
// For even k every corner cell's diagonal passes through the square's corner, so no triangle has
// all three vertices on the boundary (needed when the boundary is mapped onto straight sides).
inline Multimesh SquareGrid(int k) {
  Multimesh m;
  Points x;
  for (int j = 0; j <= k; ++j) {
    for (int i = 0; i <= k; ++i) x.emplace_back(double(i) / k, double(j) / k);
  }
  auto id = [k](int i, int j) { return j * (k + 1) + i; };
  for (int j = 0; j < k; ++j) {
    for (int i = 0; i < k; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
      } else {
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({b, c, d});
      }
    }
  }
  for (int i = 0; i < k; ++i) m.boundary.push_back(id(i, 0));
  for (int j = 0; j < k; ++j) m.boundary.push_back(id(k, j));
  for (int i = k; i > 0; --i) m.boundary.push_back(id(i, k));
  for (int j = k; j > 0; --j) m.boundary.push_back(id(0, j));
  m.shapes.push_back(x);
  return m;
}

// Every interior vertex of m (not in m.boundary) at the average of its neighbours, the boundary
// vertices where `out` has them (Tutte: injective when the boundary is a convex polygon).
inline Points TutteInterior(const Multimesh& m, Points out) {
  const int n = m.num_vertices();
  std::vector<int> index(n, -1);
  for (int v : m.boundary) index[v] = -2;
  int free = 0;
  for (int v = 0; v < n; ++v) {
    if (index[v] == -1) index[v] = free++;
  }
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(free, 2);
  for (const Triangle& t : m.triangles) {
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      for (auto [u, v] : {std::pair{a, b}, std::pair{b, a}}) {
        if (index[u] < 0) continue;
        trip.emplace_back(index[u], index[u], 0.5);
        if (index[v] >= 0) {
          trip.emplace_back(index[u], index[v], -0.5);
        } else {
          rhs.row(index[u]) += 0.5 * out[v].transpose();
        }
      }
    }
  }
  Eigen::SparseMatrix<double> l(free, free);
  l.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(l);
  const Eigen::MatrixXd sol = ldlt.solve(rhs);
  for (int v = 0; v < n; ++v) {
    if (index[v] >= 0) out[v] = sol.row(index[v]).transpose();
  }
  return out;
}

// Places the boundary (in m.boundary order) on the regular hexagon of circumradius r around
// `center`, by arc length, then the interior by TutteInterior. Same orientation as the input
// boundary.
inline Points TutteHexagon(const Multimesh& m, double r = 0.6, Point center = Point(0.5, 0.5)) {
  const Points& src = m.shapes[0];
  const int nb = static_cast<int>(m.boundary.size());
  std::vector<double> arc(nb + 1, 0.0);
  for (int b = 0; b < nb; ++b) {
    arc[b + 1] = arc[b] + (src[m.boundary[(b + 1) % nb]] - src[m.boundary[b]]).norm();
  }
  Points out = src;
  for (int b = 0; b < nb; ++b) {
    const double u = 6.0 * arc[b] / arc[nb];  // hexagon side parameter in [0, 6)
    const int side = std::min(5, static_cast<int>(u));
    const double f = u - side;
    const double a0 = -3.0 * std::numbers::pi / 4.0 + side * std::numbers::pi / 3.0;
    const Point p0 = center + r * Point(std::cos(a0), std::sin(a0));
    const Point p1 = center + r * Point(std::cos(a0 + std::numbers::pi / 3.0),
                                        std::sin(a0 + std::numbers::pi / 3.0));
    out[m.boundary[b]] = (1.0 - f) * p0 + f * p1;
  }
  return TutteInterior(m, std::move(out));
}

// x + amplitude * sin(pi x) sin(pi y) * (cos(2 pi y), sin(2 pi x)) on the unit square: fixes
// the boundary, smooth inside; injective for small amplitudes (|amplitude| <~ 0.1).
inline Points SmoothlyDistorted(const Points& x, double amplitude) {
  Points out = x;
  const double pi = std::numbers::pi;
  for (Point& p : out) {
    const double b = std::sin(pi * p.x()) * std::sin(pi * p.y());
    p += amplitude * b * Point(std::cos(2.0 * pi * p.y()), std::sin(2.0 * pi * p.x()));
  }
  return out;
}

// Similarity transform: rotate by `angle`, scale, translate.
inline Points Similar(const Points& x, double angle, double scale, Point shift) {
  Eigen::Matrix2d r;
  r << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  Points out;
  for (const Point& p : x) out.push_back(scale * (r * p) + shift);
  return out;
}

// Generated drawings for the benchmarks and the BuildMultimesh-based tests (positive orientation).
inline Drawing RegularPolygon(int sides, double radius, Point center, double phase = 0.0) {
  Drawing d;
  Outline o;
  for (int k = 0; k < sides; ++k) {
    const double a = phase + 2.0 * std::numbers::pi * k / sides;
    o.points.push_back(center + radius * Point(std::cos(a), std::sin(a)));
  }
  d.outlines.push_back(o);
  return d;
}
inline Drawing UnitSquare() {
  Drawing d;
  d.outlines.push_back({{Point(0, 0), Point(1, 0), Point(1, 1), Point(0, 1)}});
  return d;
}
// A five-pointed star, inner radius = inner_ratio * outer radius (1 = a regular decagon).
inline Drawing Star(double radius, double inner_ratio, Point center) {
  Drawing d;
  Outline o;
  for (int k = 0; k < 10; ++k) {
    const double a = -std::numbers::pi / 2 + std::numbers::pi * k / 5;
    const double r = (k % 2 == 0) ? radius : inner_ratio * radius;
    o.points.push_back(center + r * Point(std::cos(a), std::sin(a)));
  }
  d.outlines.push_back(o);
  return d;
}
// MultimeshOptions for about `vertices` vertices on a shape of area ~1 and bounding-box diagonal
// `diagonal`: edge h with 2 / (sqrt(3) h^2) vertices, boundary spacing h; CGAL's size bound is
// an upper bound, so the requested h is 1.5 times that (calibrated on square -> hexagon).
struct SizedMeshOptions {
  int boundary_vertices;
  double max_edge_relative;
};
inline SizedMeshOptions SizeFor(int vertices, double perimeter, double diagonal, double area) {
  const double h = 1.5 * std::sqrt(2.0 * area / (std::sqrt(3.0) * std::max(vertices, 4)));
  return {std::max(8, static_cast<int>(std::lround(perimeter / h))), h / diagonal};
}

// Number of triangles with non-positive signed area.
inline int CountNonPositive(const std::vector<Triangle>& triangles, const Points& x) {
  int count = 0;
  for (const Triangle& t : triangles) {
    if (!(SignedArea2(t, x) > 0.0)) ++count;
  }
  return count;
}

}  // namespace inbetween::solver::testing
