// Basic predicates on closed polygons: signed area, containment, convexity, self-intersection.
#include "solver/geometry/polygon.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace inbetween::solver {
namespace {

double Cross(const Point& a, const Point& b) { return a.x() * b.y() - a.y() * b.x(); }
double Orient(const Point& a, const Point& b, const Point& c) { return Cross(b - a, c - a); }

// c is known collinear with a-b; is it within the segment's bounding box?
bool OnSegment(const Point& a, const Point& b, const Point& c) {
  return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= c.y() && c.y() <= std::max(a.y(), b.y());
}

// Whether closed segments p1-p2 and q1-q2 share a point; *where receives one such point.
bool SegmentsMeet(const Point& p1, const Point& p2, const Point& q1, const Point& q2,
                  Point* where) {
  const double d1 = Orient(q1, q2, p1), d2 = Orient(q1, q2, p2);
  const double d3 = Orient(p1, p2, q1), d4 = Orient(p1, p2, q2);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) {
    const double t = d1 / (d1 - d2);
    *where = p1 + t * (p2 - p1);
    return true;
  }
  if (d1 == 0 && OnSegment(q1, q2, p1)) return *where = p1, true;
  if (d2 == 0 && OnSegment(q1, q2, p2)) return *where = p2, true;
  if (d3 == 0 && OnSegment(p1, p2, q1)) return *where = q1, true;
  if (d4 == 0 && OnSegment(p1, p2, q2)) return *where = q2, true;
  return false;
}

}  // namespace

double PolygonSignedArea(const Points& polygon) {
  const size_t n = polygon.size();
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) sum += Cross(polygon[i], polygon[(i + 1) % n]);
  return 0.5 * sum;
}

bool PolygonContains(const Points& polygon, const Point& q) {
  bool inside = false;
  const size_t n = polygon.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Point& a = polygon[i];
    const Point& b = polygon[j];
    if ((a.y() > q.y()) != (b.y() > q.y())) {
      const double x = a.x() + (q.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (q.x() < x) inside = !inside;
    }
  }
  return inside;
}

bool IsConvexPositive(const Points& polygon) {
  const size_t n = polygon.size();
  if (n < 3 || PolygonSignedArea(polygon) <= 0) return false;
  double scale = 0.0;
  for (size_t i = 0; i < n; ++i)
    scale = std::max(scale, (polygon[(i + 1) % n] - polygon[i]).norm());
  const double eps = 1e-12 * scale * scale;
  double winding = 0.0;  // total turning must be exactly one turn (rules out star polygons)
  for (size_t i = 0; i < n; ++i) {
    const Point e0 = polygon[(i + 1) % n] - polygon[i];
    const Point e1 = polygon[(i + 2) % n] - polygon[(i + 1) % n];
    if (Cross(e0, e1) < -eps) return false;
    winding += std::atan2(Cross(e0, e1), e0.dot(e1));
  }
  return winding < 3.0 * M_PI;
}

std::optional<SelfIntersection> FindSelfIntersection(const Points& polygon) {
  const int n = static_cast<int>(polygon.size());
  if (n < 3) return std::nullopt;
  auto a = [&](int i) -> const Point& { return polygon[i]; };
  auto b = [&](int i) -> const Point& { return polygon[(i + 1) % n]; };
  // Consecutive segments only meet at their shared vertex unless one folds back onto the other.
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const Point u = a(i) - b(i), v = b(j) - a(j);
    if (Cross(u, v) == 0 && u.dot(v) > 0) return SelfIntersection{i, j, a(j)};
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto min_x = [&](int i) { return std::min(a(i).x(), b(i).x()); };
  auto max_x = [&](int i) { return std::max(a(i).x(), b(i).x()); };
  std::sort(order.begin(), order.end(), [&](int l, int r) { return min_x(l) < min_x(r); });
  for (int oi = 0; oi < n; ++oi) {
    const int i = order[oi];
    const double xi = max_x(i);
    for (int oj = oi + 1; oj < n && min_x(order[oj]) <= xi; ++oj) {
      const int j = order[oj];
      const bool adjacent = (j == (i + 1) % n) || (i == (j + 1) % n);
      if (adjacent) continue;
      if (std::max(a(i).y(), b(i).y()) < std::min(a(j).y(), b(j).y()) ||
          std::max(a(j).y(), b(j).y()) < std::min(a(i).y(), b(i).y())) {
        continue;
      }
      Point where;
      if (SegmentsMeet(a(i), b(i), a(j), b(j), &where)) {
        return SelfIntersection{std::min(i, j), std::max(i, j), where};
      }
    }
  }
  return std::nullopt;
}

void OrientByNesting(std::vector<Outline>* outlines) {
  const size_t n = outlines->size();
  std::vector<bool> hole(n, false);
  for (size_t i = 0; i < n; ++i) {
    int depth = 0;
    // Test a point just inside the first edge to avoid vertices shared with other outlines.
    const Points& p = (*outlines)[i].points;
    const Point probe = p[0] + 1e-9 * (p[1] - p[0]);
    for (size_t j = 0; j < n; ++j) {
      if (j != i && PolygonContains((*outlines)[j].points, probe)) ++depth;
    }
    hole[i] = depth % 2 == 1;
  }
  for (size_t i = 0; i < n; ++i) {
    Points& p = (*outlines)[i].points;
    const bool positive = PolygonSignedArea(p) > 0;
    if (positive == hole[i]) std::reverse(p.begin() + 1, p.end());  // keep the first point
  }
}

}  // namespace inbetween::solver
