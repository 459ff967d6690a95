// Internal to ComputeBoundaryCorrespondence (boundary_correspondence.h), not part of the solver's
// API: the types its three stages share, and the stages' entry points.
//   1. boundary_loop_matching.cpp: every drawing's loops normalised, then matched to drawing 1's
//      loop by loop (components, then their holes) into loop groups;
//   2. boundary_parameterization.cpp: per loop group and drawing, the map from the common
//      parameter to arc length (marks, matched corners, feature or arc-length alignment);
//   3. boundary_correspondence.cpp: breakpoints, intervals and their vertex counts, and the
//      sampling of every drawing's loops at the common parameters.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"
#include "solver/geometry/affine_fit.h"
#include "solver/geometry/boundary_correspondence.h"
#include "solver/geometry/graph_flow.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver::boundary_internal {

// How far a correspondence mark may sit from the boundary it pins, relative to the length of
// that boundary loop.
inline constexpr double kMarkRelativeTolerance = 0.05;

inline double Wrap01(double t) {
  t -= std::floor(t);
  return t >= 1.0 ? 0.0 : t;
}

// A closed polyline with its cumulative arc length.
struct Curve {
  Points p;
  std::vector<double> cum;  // cum[k] = arc length at p[k]; cum[n] = perimeter
  double length() const { return cum.back(); }
  Point At(double u) const { return PointAtArcLength(p, cum, u, SegmentEnds::kExact); }
  // The arc length of the point of the loop nearest q (its distance in `distance`).
  double Project(const Point& q, double* distance) const {
    double best = std::numeric_limits<double>::infinity(), at = 0;
    for (size_t i = 0; i < p.size(); ++i) {
      const Point& a = p[i];
      const Point& b = p[(i + 1) % p.size()];
      const double t = SegmentParameter(q, a, b);
      const double dist = (a + t * (b - a) - q).norm();
      if (dist < best) best = dist, at = cum[i] + t * (cum[i + 1] - cum[i]);
    }
    if (distance) *distance = best;
    return at;
  }
};

inline Curve MakeCurve(const Points& p) {
  Curve c;
  c.p = p;
  c.cum = CumulativeLength(p);
  return c;
}

// Common parameter t in [0, 1) -> arc length on one drawing's loop: piecewise linear through
// knots (t_j, a_j), t_0 = 0, closing at (1, a_0 + length).
struct Param {
  std::vector<double> t, a;
  double length = 1;
  double Forward(double u) const {  // u may be in [0, 1]
    return Interpolate(t, a, u, 1.0, a[0] + length);
  }
  double Inverse(double arc) const {
    arc = a[0] + std::fmod(std::fmod(arc - a[0], length) + length, length);
    return Wrap01(Interpolate(a, t, arc, a[0] + length, 1.0));
  }

 private:
  // The map through knots (from[j], to[j]) and the closing knot (from_end, to_end), linear
  // between them, at x: Forward reads it one way, Inverse the other.
  static double Interpolate(const std::vector<double>& from, const std::vector<double>& to,
                            double x, double from_end, double to_end) {
    const size_t m = from.size();
    size_t j = std::upper_bound(from.begin(), from.end(), x) - from.begin();
    j = std::max<size_t>(j, 1) - 1;
    const double x1 = j + 1 < m ? from[j + 1] : from_end;
    const double y1 = j + 1 < m ? to[j + 1] : to_end;
    const double f = x1 > from[j] ? (x - from[j]) / (x1 - from[j]) : 0.0;
    return to[j] + f * (y1 - to[j]);
  }
};

// Every drawing's loops, as the matching and everything after it read them.
struct NormalisedLoops {
  std::vector<Point> centre;                 // per drawing: its bounding box's centre
  std::vector<double> scale;                 // per drawing: its bounding box's diagonal
  std::vector<std::vector<Point>> centroid;  // [d][loop]: area centroid, normalised
  std::vector<std::vector<Curve>> curves;    // [d][loop]
  int num_shapes() const { return static_cast<int>(curves.size()); }
};

NormalisedLoops NormaliseLoops(const std::vector<BoundaryGraph>& graphs);

// The loops matched across drawings: drawing 1's components in order, each followed by its
// holes (BoundaryCorrespondence::loop_outer and loop_component number them so).
struct LoopGroups {
  std::vector<std::vector<int>> loops;  // loops[g][d]: group g's loop in drawing d
  std::vector<bool> outer;
  std::vector<int> component;  // drawing 1's component index
  // carry[g][d]: the affine map of the component that carried its holes (none without holes,
  // for drawing 1, or a degenerate fit), which aligns the loops' starts.
  std::vector<std::vector<std::optional<Affine>>> carry;
  // Per group: some drawing's loop runs along a cut or an opening (ParameterizeGroup then leaves
  // its pairing to the alignment: no affine pairing).
  std::vector<bool> seamed;
  int size() const { return static_cast<int>(loops.size()); }
};

// The loop matching documented above BoundaryCorrespondence (boundary_correspondence.h): pairs
// that `marks` set, then components, then each component's holes. INVALID_ARGUMENT for marks
// that contradict each other and for matched components with different hole counts.
absl::StatusOr<LoopGroups> MatchLoopGroups(const std::vector<BoundaryGraph>& graphs,
                                           const NormalisedLoops& loops,
                                           const std::vector<std::vector<Point>>& marks);

// Best start (arc length) of `b` against `a` (both normalised): turning angle + position. With
// `carry`, `a` is first carried into b's drawing by that map (and normalised as b).
double AlignStart(const Curve& a, const Curve& b, const Point& ca, double sa, const Point& cb,
                  double sb, const Affine* carry = nullptr);

// The loops by group, as the phases after the matching read them.
struct GroupedLoops {
  const NormalisedLoops& normalised;
  const LoopGroups& groups;
  int num_shapes() const { return normalised.num_shapes(); }
  int num_groups() const { return groups.size(); }
  const Curve& curve(int d, int g) const { return normalised.curves[d][groups.loops[g][d]]; }
};

// A pin of matching points across drawings (a mark, or a corner matched to corners): its arc on
// drawing 1's loop, and its arc on the loop in every drawing.
using ArcPin = std::pair<double, std::vector<double>>;

// Per loop group and drawing, the common parameter's map to arc length, and what pins it.
struct Parameterization {
  std::vector<std::vector<Param>> param;        // param[d][g]
  std::vector<std::vector<ArcPin>> marks;       // per group: its marks, by arc on drawing 1
  std::vector<std::pair<int, double>> mark_at;  // per mark: its loop group, arc in drawing 1
  // Per group: the common parameters that marks (or matched corners) pin, each a breakpoint.
  std::vector<std::vector<double>> pinned_t;
  // aligned[d][g]: paired by the feature alignment or by matched corners (not marks).
  std::vector<std::vector<bool>> aligned;
  // affine[d][g], for an outline group: the affine map that explains the component's outline in
  // drawing d and pairs it (PairThroughAffine), which then pairs the component's holes.
  std::vector<std::vector<std::optional<Affine>>> affine;
  int corner_matched_loops = 0;
};

// The parameterizations of every loop group (marks, else the automatic alignment: see
// BoundaryCorrespondenceOptions). INVALID_ARGUMENT naming the mark for a mark with the wrong
// number of points or off every boundary, and naming the drawing for marks out of order.
absl::StatusOr<Parameterization> ParameterizeGroups(const GroupedLoops& loops,
                                                    const BoundaryCorrespondenceOptions& options);

}  // namespace inbetween::solver::boundary_internal
