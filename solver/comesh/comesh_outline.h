// Reference outlines for comesh optimization: each shape's boundary loops, frozen as closed
// polylines at the start of a run, along which boundary vertices slide (comesh_optimizer.h,
// ComeshOptions::slide_outline). A boundary vertex of a curved outline is a polyline corner in
// its own mesh (its neighbours are not collinear with it), so the straight-run sliders of the
// optimizer keep it fixed; here it moves by arc length along the polyline it started on, past the
// soft corners of that polyline, and stops at its hard ones:
//   - a turn (the angle between the incoming and outgoing segment) above corner_degrees: a
//     drawn corner (a square's 90 degrees), which the outline keeps;
//   - a point of a fixed vertex (cohesive edges, correspondence marks).
// Positions are affine along each segment, so a slid vertex stays on the frozen polyline and the
// mesh outline changes only by cutting soft corners (chords of the polyline between its new
// boundary neighbours).
//
// Arc lengths u are measured from the loop's first point and may be any real number: At() and
// Tangent() wrap them, so an unknown can cross the loop's start without a jump.
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

class ShapeOutline {
 public:
  // The loops of `mesh` (Multimesh::boundary_loops, or Multimesh::boundary as one loop) in shape
  // `shape`. A point is hard if its turn exceeds corner_degrees or its vertex is flagged in
  // `fixed` (indexed by vertex; may be shorter than the vertex count). Loops of fewer than three
  // points are left out.
  ShapeOutline(const Multimesh& mesh, int shape, double corner_degrees,
               const std::vector<char>& fixed);

  struct Location {
    int loop;
    double u;  // arc length in [0, length(loop))
  };
  // The nearest point of the outline to p if it is within `tolerance` of it (a spatial grid over
  // the segments: constant time on average).
  std::optional<Location> Locate(const Point& p, double tolerance) const;
  // The point at arc length u (wrapped).
  Point At(int loop, double u) const;
  // The unit tangent at u; at a polyline point (within 1e-12 of the loop's length) the
  // normalized sum of its two segments' tangents.
  Point Tangent(int loop, double u) const;
  // The unit tangents of the outline just before and just after u: the same vector inside a
  // segment, the two segments' directions at a polyline point (within 1e-12 of the loop's
  // length).
  std::pair<Point, Point> Tangents(int loop, double u) const;
  // True if u is within `tolerance` (arc length) of a hard point.
  bool AtHardPoint(int loop, double u, double tolerance) const;
  // The stretch of the loop around u between its hard points: (lo, hi) with lo <= u <= hi in u's
  // unwrapped frame; (-inf, +inf) if the loop has no hard point.
  std::pair<double, double> Stretch(int loop, double u) const;

  // A point to split the boundary edge (a, b) at, on the outline: the chord's midpoint if it is
  // on the outline (a straight stretch), else the middle of the shorter arc between a and b
  // when both are on the same loop and no hard point lies strictly inside that arc; otherwise
  // nothing.
  std::optional<Point> SplitPoint(const Point& a, const Point& b, double tolerance) const;

  // 1e-9 of the longest loop: the tolerance the optimizer and the topology pass locate with.
  double tolerance() const;

  // True if some loop has a soft corner: a point that turns, but by no more than corner_degrees
  // (and is not fixed). Without one, sliding along the outline is sliding along its straight
  // stretches between hard points, which the optimizer's straight sliders already do.
  bool curved() const { return curved_; }

  int num_loops() const { return static_cast<int>(loops_.size()); }
  double length(int loop) const { return loops_[loop].arc.back(); }

 private:
  struct Loop {
    std::vector<Point> points;
    std::vector<double> arc;   // arc[k] = length up to point k; arc[size] = total length
    std::vector<double> hard;  // arc lengths of hard points, ascending
  };
  // Segment k of the loop containing wrapped arc length u (in [0, length)).
  int SegmentAt(const Loop& loop, double u) const;
  double Wrap(const Loop& loop, double u) const;
  // Unit direction of segment j (taken modulo the loop's size); zero for a degenerate segment.
  Point Direction(const Loop& loop, int j) const;
  int64_t CellKey(int64_t ix, int64_t iy) const { return (ix << 32) ^ (iy & 0xffffffff); }

  std::vector<Loop> loops_;
  bool curved_ = false;
  double cell_ = 1.0;
  Point origin_ = Point::Zero();
  std::unordered_map<int64_t, std::vector<std::pair<int, int>>> grid_;  // cell -> (loop, segment)
};

}  // namespace inbetween::solver
