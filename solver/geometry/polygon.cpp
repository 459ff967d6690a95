// Basic predicates on closed polygons: containment, convexity, self-intersection.
#include "solver/geometry/polygon.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "solver/geometry/primitives.h"
#include "solver/mesh/cgal_predicates.h"

namespace inbetween::solver {

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

std::optional<SelfIntersection> FindSelfIntersection(const Points& polygon, int64_t max_pair_checks,
                                                     bool* gave_up) {
  if (gave_up != nullptr) *gave_up = false;
  const int n = static_cast<int>(polygon.size());
  if (n < 3) return std::nullopt;
  auto a = [&](int i) -> const Point& { return polygon[i]; };
  auto b = [&](int i) -> const Point& { return polygon[(i + 1) % n]; };
  // Consecutive segments only meet at their shared vertex unless one folds back onto the other.
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const Point u = a(i) - b(i), v = b(j) - a(j);
    if (ExactOrientation(a(i), b(i), b(j)) == 0 && u.dot(v) > 0) {
      return SelfIntersection{i, j, a(j)};
    }
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto min_x = [&](int i) { return std::min(a(i).x(), b(i).x()); };
  auto max_x = [&](int i) { return std::max(a(i).x(), b(i).x()); };
  std::sort(order.begin(), order.end(), [&](int l, int r) { return min_x(l) < min_x(r); });
  int64_t checks = 0;
  for (int oi = 0; oi < n; ++oi) {
    const int i = order[oi];
    const double xi = max_x(i);
    for (int oj = oi + 1; oj < n && min_x(order[oj]) <= xi; ++oj) {
      if (max_pair_checks > 0 && ++checks > max_pair_checks) {
        if (gave_up != nullptr) *gave_up = true;
        return std::nullopt;
      }
      const int j = order[oj];
      const bool adjacent = (j == (i + 1) % n) || (i == (j + 1) % n);
      if (adjacent) continue;
      if (std::max(a(i).y(), b(i).y()) < std::min(a(j).y(), b(j).y()) ||
          std::max(a(j).y(), b(j).y()) < std::min(a(i).y(), b(i).y())) {
        continue;
      }
      const SegmentContact contact = ExactSegmentContact(a(i), b(i), a(j), b(j));
      if (contact.kind != SegmentContact::kNone) {
        return SelfIntersection{std::min(i, j), std::max(i, j), contact.point};
      }
    }
  }
  return std::nullopt;
}

void OrientByNesting(std::vector<Outline>* outlines) {
  const size_t n = outlines->size();
  std::vector<bool> hole(n, false);
  // Bounding boxes first: a point outside an outline's box is outside the outline (drawings of
  // thousands of separate shapes test each point against a few boxes, not every outline).
  std::vector<Eigen::AlignedBox2d> boxes(n);
  for (size_t j = 0; j < n; ++j) {
    for (const Point& q : (*outlines)[j].points) boxes[j].extend(q);
  }
  for (size_t i = 0; i < n; ++i) {
    int depth = 0;
    // Test a point just inside the first edge to avoid vertices shared with other outlines.
    const Points& p = (*outlines)[i].points;
    const Point probe = p[0] + 1e-9 * (p[1] - p[0]);
    for (size_t j = 0; j < n; ++j) {
      if (j != i && boxes[j].contains(probe) && PolygonContains((*outlines)[j].points, probe)) {
        ++depth;
      }
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
