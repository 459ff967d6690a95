// The plane's small primitives, each defined once: the 2D cross product, signed areas of
// triangles and polygons, the point of a segment nearest to a point, the arc-length lookup on a
// closed polyline and the index check of a triangle.
//
// Each formula has one fixed operation order (a.x * b.y - a.y * b.x, sums in index order) that
// every caller's results depend on bit for bit: do not reorder or "simplify" them. Use these
// rather than a local copy, so that a caller cannot drift from the others.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// a.x * b.y - a.y * b.x: positive when b lies counter-clockwise of a in y-up axes (clockwise on
// an SVG y-down screen), the sense of types.h's "positive" orientation.
inline double Cross(const Point& a, const Point& b) { return a.x() * b.y() - a.y() * b.x(); }

// Twice the signed area of triangle abc, Cross(b - a, c - a); positive as in types.h.
inline double SignedArea2(const Point& a, const Point& b, const Point& c) {
  return Cross(b - a, c - a);
}

// Twice the signed area of triangle t of the points x.
inline double SignedArea2(const Triangle& t, const Points& x) {
  return SignedArea2(x[t[0]], x[t[1]], x[t[2]]);
}

// Twice the signed area of the closed polygon: sum of Cross(p_i, p_{i+1}) in index order.
inline double PolygonSignedArea2(const Points& polygon) {
  const size_t n = polygon.size();
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) sum += Cross(polygon[i], polygon[(i + 1) % n]);
  return sum;
}

// Signed area 0.5 * sum(x_i * y_{i+1} - x_{i+1} * y_i); positive = the convention of types.h.
inline double PolygonSignedArea(const Points& polygon) { return 0.5 * PolygonSignedArea2(polygon); }

// The parameter t in [0, 1] of the point a + t (b - a) of segment a-b nearest to p. NaN when
// a == b (0 / 0; NaN compares false, so a "nearest so far" test skips it): callers that want a
// point there use NearestOnSegment.
inline double SegmentParameter(const Point& p, const Point& a, const Point& b) {
  const Point d = b - a;
  return std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
}

// The point of segment a-b nearest to p (a when a == b).
inline Point NearestOnSegment(const Point& p, const Point& a, const Point& b) {
  const Point d = b - a;
  if (d.squaredNorm() == 0) return a;
  return a + SegmentParameter(p, a, b) * d;
}

// The distance from p to segment a-b.
inline double DistanceToSegment(const Point& p, const Point& a, const Point& b) {
  return (NearestOnSegment(p, a, b) - p).norm();
}

// Cumulative arc length of the closed polyline p: cum[k] at p[k], cum[n] the perimeter.
inline std::vector<double> CumulativeLength(const Points& p) {
  const size_t n = p.size();
  std::vector<double> cum(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) cum[i + 1] = cum[i] + (p[(i + 1) % n] - p[i]).norm();
  return cum;
}

// What PointAtArcLength returns at the ends of a segment. The two differ only in rounding:
// p[i] + 1.0 * (p[i + 1] - p[i]) need not equal p[i + 1] exactly.
enum class SegmentEnds {
  kInterpolate,  // p[i] + t (p[i + 1] - p[i]) for every t, the ends included
  kExact,        // p[i] itself at t = 0 and p[i + 1] itself at t = 1
};

// The point at arc length u (taken modulo the perimeter) of the closed polyline p with
// cumulative lengths cum (CumulativeLength). Segment i spans [cum[i], cum[i + 1]); a
// zero-length segment gives its start.
inline Point PointAtArcLength(const Points& p, const std::vector<double>& cum, double u,
                              SegmentEnds ends) {
  const double total = cum.back();
  u = std::fmod(u, total);
  if (u < 0) u += total;
  const size_t n = p.size();
  size_t i = std::upper_bound(cum.begin(), cum.end(), u) - cum.begin();
  i = std::clamp<size_t>(i, 1, n) - 1;
  const double len = cum[i + 1] - cum[i];
  const double t = len > 0 ? std::clamp((u - cum[i]) / len, 0.0, 1.0) : 0.0;
  if (ends == SegmentEnds::kExact) {
    if (t == 0.0) return p[i];
    if (t == 1.0) return p[(i + 1) % n];
  }
  return p[i] + t * (p[(i + 1) % n] - p[i]);
}

// Index checks of a triangle of a mesh with n vertices; callers word the error.
// The first of t's vertex indices outside [0, n), or nullopt when all three are in range.
inline std::optional<int> IndexOutOfRange(const Triangle& t, int n) {
  for (int v : t) {
    if (v < 0 || v >= n) return v;
  }
  return std::nullopt;
}

// True when two of t's vertex indices are equal.
inline bool RepeatsVertex(const Triangle& t) {
  return t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
}

}  // namespace inbetween::solver
