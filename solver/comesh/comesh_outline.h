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
  // Closed polylines given as points (a drawing's outlines: the reference OutlineGuard measures
  // against); every turn above corner_degrees is hard.
  ShapeOutline(const std::vector<Points>& loops, double corner_degrees);

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

  // How far the chord a-b strays from the outline it replaces: the largest distance from the
  // segment a-b of the outline's points strictly inside the shorter arc between a and b (both
  // located within `locate_tolerance`; 0 if either is not, or they are on different loops: the
  // chord then runs along a cut or an opening, not the outline). For the short arcs a boundary
  // edge spans this is the Hausdorff distance between chord and arc.
  double ChordDeviation(const Point& a, const Point& b, double locate_tolerance) const;

  // The diagonal of the outline's bounding box.
  double diagonal() const { return diagonal_; }

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
  // Points of each loop and whether point k is hard, then arcs, bounding box and the grid.
  void Init(const std::vector<Points>& loops, const std::vector<std::vector<char>>& fixed,
            double corner_degrees);

  std::vector<Loop> loops_;
  bool curved_ = false;
  double cell_ = 1.0;
  Point origin_ = Point::Zero();
  double diagonal_ = 0.0;
  std::unordered_map<int64_t, std::vector<std::pair<int, int>>> grid_;  // cell -> (loop, segment)
};

// Keeps comesh optimization from cutting a drawing's tips: outline sliders (comesh_optimizer.h)
// move along the frozen input outline, so the mesh outline changes only by chords across the soft
// corners a vertex has left, and at a rounded tip drawn with many small turns those chords cut
// the tip off. The guard holds every chord at an outline slider within `tolerance` of a reference
// outline (ShapeOutline::ChordDeviation): the drawing's own outline when given, else the input
// mesh's. A chord that already strays further when the run starts (a build with a fixed vertex
// count) may keep its deviation but not grow it.
class OutlineGuard {
 public:
  // reference[s]: shape s's reference outline (not owned; must outlive the guard); tolerance[s]
  // its bound in its own units.
  OutlineGuard(std::vector<const ShapeOutline*> reference, std::vector<double> tolerance);

  // Registers the chords of boundary vertex v of shape s with its boundary neighbours prev and
  // next at positions x (the run's start); returns the slot Holds and HoldsAt take.
  int Add(int s, int v, int prev, int next, const Points& x);

  // True if slot i's two chords are within their bound with its vertex at p and the neighbours
  // at x.
  bool HoldsAt(int i, const Point& p, const Points& x) const;
  // True if every slot's chords are within their bounds at `shapes`.
  bool Holds(const std::vector<Points>& shapes) const;

 private:
  struct Slot {
    int shape, vertex, prev, next;
    double allowed_prev, allowed_next;  // the bound of chord prev-v and of chord v-next
  };
  double Deviation(int s, const Point& a, const Point& b) const;

  std::vector<const ShapeOutline*> reference_;
  std::vector<double> tolerance_;
  std::vector<Slot> slots_;
};

}  // namespace inbetween::solver
