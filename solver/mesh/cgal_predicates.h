// Exact geometric predicates (CGAL's filtered exact kernel) for the planar straight-line graph.
// The header is CGAL-free; only cgal_predicates.cpp includes the kernel.
#pragma once

#include <optional>

#include "solver/core/types.h"

namespace inbetween::solver {

// Sign of the orientation of (a, b, c), computed exactly: +1 when c is to the left of a->b
// (positive signed area), -1 to the right, 0 when collinear.
int ExactOrientation(const Point& a, const Point& b, const Point& c);

// How two closed segments p1-p2 and q1-q2 meet, decided with exact predicates.
struct SegmentContact {
  enum Kind { kNone, kCross, kTouch, kOverlap } kind = kNone;
  // kCross: the crossing point (rounded) and its parameters along each segment in (0, 1).
  // kTouch: an endpoint of one segment lying on the other (the endpoint itself, exact).
  // kOverlap: collinear segments sharing more than one point; `point` is one shared point.
  Point point = Point::Zero();
  double t_p = 0.0;
  double t_q = 0.0;
};
SegmentContact ExactSegmentContact(const Point& p1, const Point& p2, const Point& q1,
                                   const Point& q2);

}  // namespace inbetween::solver
