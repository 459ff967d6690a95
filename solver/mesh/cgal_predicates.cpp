// Exact orientation and segment-contact predicates (CGAL Exact_predicates_inexact_constructions
// kernel). Used by the planar straight-line graph of S-Sec.1 / S-Alg.1 (graph_flow.cpp) so that
// crossings between outlines, cuts and openings are decided exactly; only the crossing point
// itself is rounded. Kept separate from cgal_triangulate.cpp: this unit only needs the kernel.
#include "solver/mesh/cgal_predicates.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>

#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using P2 = K::Point_2;

P2 ToCgal(const Point& p) { return P2(p.x(), p.y()); }

// c is collinear with a-b: is it inside the closed segment?
bool Between(const Point& a, const Point& b, const Point& c) {
  return CGAL::collinear_are_ordered_along_line(ToCgal(a), ToCgal(c), ToCgal(b));
}

}  // namespace

int ExactOrientation(const Point& a, const Point& b, const Point& c) {
  switch (CGAL::orientation(ToCgal(a), ToCgal(b), ToCgal(c))) {
    case CGAL::LEFT_TURN:
      return 1;
    case CGAL::RIGHT_TURN:
      return -1;
    default:
      return 0;
  }
}

SegmentContact ExactSegmentContact(const Point& p1, const Point& p2, const Point& q1,
                                   const Point& q2) {
  SegmentContact out;
  const int d1 = ExactOrientation(q1, q2, p1), d2 = ExactOrientation(q1, q2, p2);
  const int d3 = ExactOrientation(p1, p2, q1), d4 = ExactOrientation(p1, p2, q2);
  if (d1 * d2 < 0 && d3 * d4 < 0) {
    // Proper crossing: the point from the exactly-signed but rounded orientation values.
    const double o1 = Cross(q2 - q1, p1 - q1), o2 = Cross(q2 - q1, p2 - q1);
    const double o3 = Cross(p2 - p1, q1 - p1), o4 = Cross(p2 - p1, q2 - p1);
    out.kind = SegmentContact::kCross;
    out.t_p = std::clamp(o1 / (o1 - o2), 0.0, 1.0);
    out.t_q = std::clamp(o3 / (o3 - o4), 0.0, 1.0);
    out.point = p1 + out.t_p * (p2 - p1);
    return out;
  }
  if (d1 == 0 && d2 == 0) {  // collinear: compare the parameter intervals along p
    const Point d = p2 - p1;
    const double len = d.squaredNorm();
    if (len == 0) return out;
    const double a = (q1 - p1).dot(d) / len, b = (q2 - p1).dot(d) / len;
    const double lo = std::max(0.0, std::min(a, b)), hi = std::min(1.0, std::max(a, b));
    if (lo > hi) return out;
    out.kind = lo == hi ? SegmentContact::kTouch : SegmentContact::kOverlap;
    out.t_p = lo;
    out.point = lo == 0.0 ? p1 : lo == 1.0 ? p2 : (a < b ? q1 : q2);
    out.t_q = SegmentParameter(out.point, q1, q2);
    return out;
  }
  for (const auto& [c, on_q] :
       {std::pair<Point, bool>{p1, true}, {p2, true}, {q1, false}, {q2, false}}) {
    const bool collinear =
        on_q ? ExactOrientation(q1, q2, c) == 0 : ExactOrientation(p1, p2, c) == 0;
    if (collinear && (on_q ? Between(q1, q2, c) : Between(p1, p2, c))) {
      out.kind = SegmentContact::kTouch;
      out.point = c;
      out.t_p = SegmentParameter(c, p1, p2);
      out.t_q = SegmentParameter(c, q1, q2);
      return out;
    }
  }
  return out;
}

}  // namespace inbetween::solver
