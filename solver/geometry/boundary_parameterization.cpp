// The parameterization step of ComputeBoundaryCorrespondence: per loop group and drawing, the
// map from the common parameter to arc length. Marks pin matching points (snapped onto nearby
// corners) with arc length between them; without marks, corners matched to corners do the same
// (BoundaryCorrespondenceOptions::match_corners), else the feature alignment (loop_alignment.h)
// or arc length from the automatically aligned start.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>

#include "absl/strings/str_cat.h"
#include "solver/geometry/boundary_correspondence_internal.h"
#include "solver/geometry/loop_alignment.h"
#include "solver/geometry/primitives.h"
#include "solver/geometry/resample_outline.h"

namespace inbetween::solver::boundary_internal {
namespace {

// Below this misfit (CarriedMisfit) the component's affine map explains a carried loop, and arc
// length from the carried start pairs it (a sheared flower: arc length 0.5-0.7 units off the
// affine correspondence, the alignment 1.5-2.8); above it the loop is aligned.
constexpr double kCarriedMisfit = 0.02;
// A hole that the outline's correspondence carries within this mean distance (relative to the
// hole's length) of the other drawing's hole is aligned by features (AlignCarriedOutline,
// AlignCarriedHole).
constexpr double kHoleMisfit = 0.05;
// Below this mean distance (relative to drawing d's loop length) from drawing 1's loop carried by
// an affine map to drawing d's loop, the map explains the pair, which is then paired through it
// point by point (PairThroughAffine).
constexpr double kAffineMisfit = 0.002;

// A mark computed by a program lands a hair off the drawn corner (an SVG written with four
// decimals puts it 5e-5 units, 1e-7 of the diagonal, from an arrow's corner); pinned there it
// splits the boundary next to the corner's own breakpoint into a sliver interval that every
// drawing must repeat, and the mesher then fails on the sliver in another drawing. So a mark
// within this fraction of its drawing's bounding-box diagonal of a corner of the loop
// (FindCorners at corner_angle_degrees) snaps onto that corner, else onto the nearest vertex of
// the loop within it (BoundaryCorrespondenceOptions::marks).
constexpr double kMarkSnapRelative = 1e-5;

// A corner of a loop: its arc length, the sign of its turn (+1 convex, -1 reflex, for a loop
// with the drawing on its left) and the turn's angle (radians, unsigned).
struct Corner {
  double arc;
  int turn;
  double angle;
};

// The corners of `c` (FindCorners at corner_angle_degrees), by arc length.
std::vector<Corner> CornersOf(const Curve& c, double corner_angle_degrees) {
  std::vector<Corner> out;
  const size_t n = c.p.size();
  for (int k : FindCorners(c.p, corner_angle_degrees)) {
    const Point in = c.p[k] - c.p[(k + n - 1) % n], next = c.p[(k + 1) % n] - c.p[k];
    const double cross = Cross(in, next);
    out.push_back({c.cum[k], cross > 0.0 ? 1 : -1, std::atan2(std::abs(cross), in.dot(next))});
  }
  std::sort(out.begin(), out.end(), [](const Corner& a, const Corner& b) { return a.arc < b.arc; });
  return out;
}

// Automatic corner matching (BoundaryCorrespondenceOptions::match_corners): for one loop group
// without marks, pairs of (arc in drawing 1, arcs in every drawing) of corners matched to
// corners, or nothing. Every drawing must have as many corners on the loop as drawing 1; they are
// matched in cyclic order, each pair turning the same way, at the shift that best agrees in the
// pairs' turn angles and with the automatic alignment (`start`: drawing d's arc aligned with
// drawing 1's arc 0). The turn angles weigh kTurnWeight times more: corners are matched when arc
// length failed, often because the alignment is far off (a needle's tip aligned with its blunt
// end, half the loop away), while the turn angles tell the tip from the other corners; the
// alignment decides between corners that turn alike (a square's, a parallelogram's).
// Corners are first every vertex turning by more than kFineCornerDegrees (a polygon and its
// affine copy: vertex onto vertex); if their counts differ, every vertex that is not collinear
// with its neighbours (turning by more than kCollinearDegrees: a shear can take a vertex's turn
// across 1 degree, but an affine map keeps collinear points collinear); else those above
// `corner_angle_degrees`.
constexpr double kFineCornerDegrees = 1.0;
constexpr double kCollinearDegrees = 1e-6;
constexpr double kTurnWeight = 10.0;

std::vector<ArcPin> MatchCornersAbove(const std::vector<const Curve*>& curves,
                                      const std::vector<double>& start,
                                      double corner_angle_degrees);

std::vector<ArcPin> MatchCorners(const std::vector<const Curve*>& curves,
                                 const std::vector<double>& start, double corner_angle_degrees) {
  for (double degrees : {std::min(kFineCornerDegrees, corner_angle_degrees), kCollinearDegrees,
                         corner_angle_degrees}) {
    auto pairs = MatchCornersAbove(curves, start, degrees);
    if (!pairs.empty()) return pairs;
  }
  return {};
}

std::vector<ArcPin> MatchCornersAbove(const std::vector<const Curve*>& curves,
                                      const std::vector<double>& start,
                                      double corner_angle_degrees) {
  const int num_shapes = static_cast<int>(curves.size());
  const std::vector<Corner> first = CornersOf(*curves[0], corner_angle_degrees);
  const int n = static_cast<int>(first.size());
  if (n == 0) return {};
  std::vector<ArcPin> pairs(n);
  for (int i = 0; i < n; ++i) {
    pairs[i] = {first[i].arc, std::vector<double>(num_shapes)};
    pairs[i].second[0] = first[i].arc;
  }
  for (int d = 1; d < num_shapes; ++d) {
    const Curve& c = *curves[d];
    std::vector<Corner> corners = CornersOf(c, corner_angle_degrees);
    if (static_cast<int>(corners.size()) != n) return {};
    // Corner fractions of the loop, counted from the aligned start, in increasing order.
    std::vector<std::pair<double, int>> at;
    for (int j = 0; j < n; ++j) at.push_back({Wrap01((corners[j].arc - start[d]) / c.length()), j});
    std::sort(at.begin(), at.end());
    int best = -1;
    double best_cost = std::numeric_limits<double>::infinity();
    for (int r = 0; r < n; ++r) {
      double cost = 0.0;
      for (int i = 0; i < n && cost < best_cost; ++i) {
        const auto& [fraction, j] = at[(i + r) % n];
        const double gap = std::abs(fraction - first[i].arc / curves[0]->length());
        const double dist = std::min(gap, 1.0 - gap);
        if (corners[j].turn != first[i].turn) {
          cost = std::numeric_limits<double>::infinity();
        }
        const double turn = (corners[j].angle - first[i].angle) / std::numbers::pi;
        cost += dist * dist + kTurnWeight * turn * turn;
      }
      if (cost < best_cost) best_cost = cost, best = r;
    }
    if (best < 0) return {};
    // The matched corners' arcs, measured from the first pair's corner, must increase strictly
    // (else no match).
    const double first_arc = corners[at[best].second].arc;
    double previous = -1.0;
    for (int i = 0; i < n; ++i) {
      const double arc = corners[at[(i + best) % n].second].arc;
      const double from_first = std::fmod(arc - first_arc + c.length(), c.length());
      if (!(from_first > previous)) return {};
      previous = from_first;
      pairs[i].second[d] = arc;
    }
  }
  return pairs;
}

// Arc length `at` on `c` snapped onto the nearest corner within `tolerance`, else the nearest
// vertex within it, else unchanged (kMarkSnapRelative). Distances are along the loop: a loop
// that passes twice through one point (the two sides of a cut) must not send the mark to the
// other pass.
double SnapMark(const Curve& c, double at, double tolerance, double corner_angle_degrees) {
  const double length = c.length();
  auto nearest = [&](const std::vector<int>& indices) {
    int best = -1;
    double best_dist = tolerance;
    for (int k : indices) {
      const double gap = std::abs(c.cum[k] - at);
      const double dist = std::min(gap, length - gap);
      if (dist <= best_dist) best_dist = dist, best = k;
    }
    return best;
  };
  int k = nearest(FindCorners(c.p, corner_angle_degrees));
  if (k < 0) {
    std::vector<int> all(c.p.size());
    std::iota(all.begin(), all.end(), 0);
    k = nearest(all);
  }
  return k < 0 ? at : c.cum[k];
}

// A mark placed on its loop group: the group, and its arc on the group's loop in every drawing
// (snapped, SnapMark).
struct PlacedMark {
  int group = -1;
  std::vector<double> at;
};

// Mark m (`mark`: its point in every drawing) placed on the loop group nearest its point in
// drawing 1. INVALID_ARGUMENT naming the mark when it has the wrong number of points or sits far
// from that loop in some drawing: a mark far away is a mistake, not a pin.
absl::StatusOr<PlacedMark> PlaceMark(const GroupedLoops& loops, const std::vector<Point>& mark,
                                     size_t m, double corner_angle_degrees) {
  const int num_shapes = loops.num_shapes();
  if (static_cast<int>(mark.size()) != num_shapes) {
    return absl::InvalidArgumentError(absl::StrCat("mark ", m + 1, " has ", mark.size(),
                                                   " points for ", num_shapes, " drawings"));
  }
  PlacedMark out;
  double best = std::numeric_limits<double>::infinity(), at0 = 0;
  for (int g = 0; g < loops.num_groups(); ++g) {
    double dist;
    const double a = loops.curve(0, g).Project(mark[0], &dist);
    if (dist < best) best = dist, out.group = g, at0 = a;
  }
  out.at.assign(num_shapes, at0);
  for (int d = 0; d < num_shapes; ++d) {
    const Curve& c = loops.curve(d, out.group);
    double dist = best;
    if (d > 0) out.at[d] = c.Project(mark[d], &dist);
    out.at[d] =
        SnapMark(c, out.at[d], kMarkSnapRelative * loops.normalised.scale[d], corner_angle_degrees);
    if (!(dist <= kMarkRelativeTolerance * c.length())) {
      const Point& p = mark[d];
      return absl::InvalidArgumentError(
          absl::StrCat("drawing ", d + 1, ": correspondence mark ", m + 1, " at (", p.x(), ", ",
                       p.y(), ") is ", dist, " from the nearest boundary, more than ",
                       kMarkRelativeTolerance * 100, "% of that boundary's length"));
    }
  }
  return out;
}

// Group g's start in every drawing: the arc aligned with drawing 1's arc 0 (AlignStart, drawing
// 1's loop carried by its component's map where one carried the holes).
std::vector<double> AlignedStarts(const GroupedLoops& loops, int g) {
  const NormalisedLoops& n = loops.normalised;
  std::vector<double> start(loops.num_shapes(), 0.0);
  for (int d = 1; d < loops.num_shapes(); ++d) {
    const std::optional<Affine>& carry = loops.groups.carry[g][d];
    start[d] = AlignStart(loops.curve(0, g), loops.curve(d, g), n.centre[0], n.scale[0],
                          n.centre[d], n.scale[d], carry.has_value() ? &*carry : nullptr);
  }
  return start;
}

// The mean distance, relative to the loop's length, between drawing 1's loop carried by its
// component's affine map and drawing d's loop at arc length from the carried start `start`.
double CarriedMisfit(const Curve& a, const Curve& b, const Affine& carry, double start) {
  constexpr int kSamples = 64;
  double sum = 0.0;
  for (int k = 0; k < kSamples; ++k) {
    sum +=
        (carry(a.At(a.length() * k / kSamples)) - b.At(start + b.length() * k / kSamples)).norm();
  }
  return sum / kSamples / b.length();
}

// Drawing d's image of a point of drawing 1 inside a component, through the correspondence of
// the component's outline: the point's mean value coordinates (Floater 2003) in drawing 1's
// outline, sampled at kSamples common parameters, applied to drawing d's outline at the same
// parameters. It reproduces an affine map and follows a bend, which no one affine map does; it
// carries a hole of a bent drawing onto that drawing's hole.
class OutlineMap {
 public:
  OutlineMap(const Curve& c0, const Param& p0, const Curve& cd, const Param& pd) {
    for (int k = 0; k < kSamples; ++k) {
      const double t = static_cast<double>(k) / kSamples;
      from_.push_back(c0.At(p0.Forward(t)));
      to_.push_back(cd.At(pd.Forward(t)));
    }
  }

  Point operator()(const Point& q) const {
    std::array<double, kSamples> r;
    std::array<Point, kSamples> e;
    for (int k = 0; k < kSamples; ++k) {
      e[k] = from_[k] - q;
      r[k] = e[k].norm();
      if (r[k] < 1e-12) return to_[k];
    }
    // tan(alpha_k / 2) of the angle at q between samples k and k + 1.
    std::array<double, kSamples> half;
    for (int k = 0; k < kSamples; ++k) {
      const int k1 = (k + 1) % kSamples;
      const double denominator = r[k] * r[k1] + e[k].dot(e[k1]);
      half[k] = denominator > 0 ? Cross(e[k], e[k1]) / denominator : 0.0;
    }
    Point sum = Point::Zero();
    double total = 0.0;
    for (int k = 0; k < kSamples; ++k) {
      const double w = (half[(k + kSamples - 1) % kSamples] + half[k]) / r[k];
      sum += w * to_[k], total += w;
    }
    return std::abs(total) > 0 ? Point(sum / total) : q;
  }

 private:
  static constexpr int kSamples = 256;
  Points from_, to_;
};

// The mean distance from drawing 1's loop carried point by point into drawing d (`carried`) to
// drawing d's loop `b`, relative to b's length. (Not boundary_loop_matching.cpp's
// CarriedDistance, a mean squared distance between arc-length samples that scores matchings.)
double MeanDistanceToLoop(const Points& carried, const Curve& b) {
  const Curve c = MakeCurve(carried);
  constexpr int kSamples = 64;
  double sum = 0.0;
  for (int k = 0; k < kSamples; ++k) {
    double dist;
    b.Project(c.At(c.length() * k / kSamples), &dist);
    sum += dist;
  }
  return sum / kSamples / b.length();
}

// Group g's loop in drawing d paired with drawing 1's by the feature alignment
// (loop_alignment.h), the aligned start `start` one of the starts it tries; `p` holds the loop's
// length and receives the knots. `carried`, when given: drawing 1's loop carried vertex by
// vertex into drawing d, aligned in drawing d's frame instead of drawing 1's loop in its own (a
// map that explains part of the deformation then changes no turn the alignment weighs; what it
// leaves unexplained is what the alignment pairs by features). Its knots are read back onto
// drawing 1's loop through the vertices.
void AlignFeatures(const GroupedLoops& loops, int g, int d, double start,
                   double corner_angle_degrees, const Points* carried, Param* p) {
  const NormalisedLoops& n = loops.normalised;
  // Both loops in their drawings' normalised frames, for the alignment's position term.
  const Curve& c0 = loops.curve(0, g);
  Points a = carried != nullptr ? *carried : c0.p, b = loops.curve(d, g).p;
  const int frame = carried != nullptr ? d : 0;
  for (Point& q : a) q = (q - n.centre[frame]) / n.scale[frame];
  for (Point& q : b) q = (q - n.centre[d]) / n.scale[d];
  LoopAlignmentOptions align;
  align.corner_angle_degrees = corner_angle_degrees;
  const LoopAlignment al = AlignLoops(a, b, start / p->length, align);
  const std::vector<double> cum = CumulativeLength(a);
  for (size_t k = 0; k < al.a.size(); ++k) {
    double t = al.a[k];
    if (carried != nullptr) {  // the fraction of a's length, as a fraction of drawing 1's loop
      const double arc = t * cum.back();
      const size_t i = std::min<size_t>(
          std::upper_bound(cum.begin(), cum.end(), arc) - cum.begin() - 1, a.size() - 1);
      const double len = cum[i + 1] - cum[i];
      const double f = len > 0 ? (arc - cum[i]) / len : 0.0;
      t = (c0.cum[i] + f * (c0.cum[i + 1] - c0.cum[i])) / c0.length();
      if (!p->t.empty() && !(t > p->t.back())) continue;
    }
    p->t.push_back(t);
    p->a.push_back(al.b[k] * p->length);
  }
}

// Knots at the pins (marks or matched corners) of drawing d, arc length between them; `p` holds
// the loop's length. INVALID_ARGUMENT when the pins are not in drawing 1's cyclic order.
absl::Status KnotsAtPins(const std::vector<ArcPin>& pins, int d, double len0, Param* p) {
  const double base0 = pins[0].first, based = pins[0].second[d];
  for (size_t j = 0; j < pins.size(); ++j) {
    double a = pins[j].second[d] - based;
    a = std::fmod(a + p->length, p->length);
    if (j > 0 && !(a > p->a.back() - based)) {
      return absl::InvalidArgumentError(
          absl::StrCat("drawing ", d + 1,
                       ": correspondence marks on one boundary are not in the same "
                       "order as in drawing 1 (or two marks coincide)"));
    }
    p->t.push_back((pins[j].first - base0) / len0);
    p->a.push_back(based + a);
  }
  return absl::OkStatus();
}

// Drawing 1's loop of group g carried into drawing d point by point by `map`.
template <typename Map>
Points Carried(const GroupedLoops& loops, int g, const Map& map) {
  Points out;
  for (const Point& q : loops.curve(0, g).p) out.push_back(map(q));
  return out;
}

// The holes of outline group g's component: the groups after it up to the next outline.
std::vector<int> HoleGroups(const GroupedLoops& loops, int g) {
  std::vector<int> holes;
  for (int h = g + 1; h < loops.num_groups() && !loops.groups.outer[h] &&
                      loops.groups.component[h] == loops.groups.component[g];
       ++h) {
    holes.push_back(h);
  }
  return holes;
}

// The outline of hole group h's component.
int OutlineGroup(const GroupedLoops& loops, int h) {
  int g = h;
  while (g > 0 && !loops.groups.outer[g]) --g;
  return g;
}

// Drawing 1's loop of group g paired with drawing d's through the affine map `carry`: each
// vertex of drawing 1's loop, carried, onto the nearest point of drawing d's loop (knots in
// drawing 1's order; one that does not advance, or leaps past what the map could stretch, is
// left out). Where the map explains the pair this is its correspondence to the flattening,
// which neither arc length (an affine map stretches directions differently) nor the alignment
// (its knots are samples a 192nd of the loop apart) gives near a sharp tip.
Param ProjectThrough(const GroupedLoops& loops, int g, int d, const Affine& carry) {
  const Curve& c0 = loops.curve(0, g);
  const Curve& cd = loops.curve(d, g);
  Param out;
  out.length = cd.length();
  const int n = static_cast<int>(c0.p.size());
  // At most kMaxKnots knots: each projection reads the whole loop.
  constexpr int kMaxKnots = 2048;
  const int stride = std::max(1, (n + kMaxKnots - 1) / kMaxKnots);
  const double stretch = std::max(1.0, carry.m.norm()) * 4.0;
  for (int i = 0; i < n; i += stride) {
    double unused;
    const double arc = cd.Project(carry(c0.p[i]), &unused);
    const double t = c0.cum[i] / c0.length();
    if (i == 0) {
      out.t.push_back(0.0), out.a.push_back(arc);
      continue;
    }
    const double a = out.a[0] + std::fmod(arc - out.a[0] + 2 * cd.length(), cd.length());
    const double leap = stretch * (t - out.t.back()) * c0.length() + 1e-3 * cd.length();
    if (!(a > out.a.back()) || a - out.a.back() > leap) continue;
    out.t.push_back(t), out.a.push_back(a);
  }
  return out;
}

// The least-squares affine map of drawing 1's loop of group g onto drawing d's as `p` pairs them
// (64 common parameters), or nothing for a degenerate fit.
std::optional<Affine> FitThrough(const GroupedLoops& loops, int g, int d, const Param& p0,
                                 const Param& p) {
  constexpr int kSamples = 64;
  std::vector<std::pair<Point, Point>> pairs;
  for (int k = 0; k < kSamples; ++k) {
    const double t = static_cast<double>(k) / kSamples;
    pairs.emplace_back(loops.curve(0, g).At(p0.Forward(t)), loops.curve(d, g).At(p.Forward(t)));
  }
  Affine fit;
  if (!FitAffine(pairs, &fit)) return std::nullopt;
  return fit;
}

// The point of loop `c` nearest q, and the unit direction of the segment it lies on.
std::pair<Point, Point> NearestWithDirection(const Curve& c, const Point& q) {
  double best = std::numeric_limits<double>::infinity();
  Point at = c.p[0], dir(1, 0);
  const size_t n = c.p.size();
  for (size_t i = 0; i < n; ++i) {
    const Point& a = c.p[i];
    const Point& b = c.p[(i + 1) % n];
    const Point x = NearestOnSegment(q, a, b);
    const double dist = (x - q).squaredNorm();
    if (dist < best && (b - a).squaredNorm() > 0) best = dist, at = x, dir = (b - a).normalized();
  }
  return {at, dir};
}

// Points of drawing 1 with the loop of the other drawing they belong on.
struct LoopPoints {
  Points from;
  const Curve* to;
};

// One step of affine ICP (point to line): the affine map taking each point of `sets` to the line
// through its current image's nearest point of its loop along that point's segment, with a small
// pull (kPointWeight) to the nearest point itself, which fixes what the lines leave free (a
// circle's turn). The mean distance of each set's current images from its loop in `misfit`
// (absolute).
std::optional<Affine> PointToLineStep(const std::vector<LoopPoints>& sets, const Affine& current,
                                      std::vector<double>* misfit) {
  constexpr double kPointWeight = 0.01;
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  // Unknowns: m00, m01, m10, m11, t0, t1.
  auto add = [&](const Eigen::Matrix<double, 6, 1>& row, double rhs, double w) {
    ata += w * row * row.transpose();
    atb += w * row * rhs;
  };
  misfit->clear();
  for (const LoopPoints& set : sets) {
    double sum = 0.0;
    for (const Point& a : set.from) {
      const Point image = current(a);
      const auto [q, dir] = NearestWithDirection(*set.to, image);
      sum += (q - image).norm();
      const Point nrm(-dir.y(), dir.x());
      Eigen::Matrix<double, 6, 1> row;
      row << nrm.x() * a.x(), nrm.x() * a.y(), nrm.y() * a.x(), nrm.y() * a.y(), nrm.x(), nrm.y();
      add(row, nrm.dot(q), 1.0);
      Eigen::Matrix<double, 6, 1> rx, ry;
      rx << a.x(), a.y(), 0, 0, 1, 0;
      ry << 0, 0, a.x(), a.y(), 0, 1;
      add(rx, q.x(), kPointWeight);
      add(ry, q.y(), kPointWeight);
    }
    misfit->push_back(set.from.empty() ? 0.0 : sum / static_cast<double>(set.from.size()));
  }
  const Eigen::Matrix<double, 6, 1> x = ata.ldlt().solve(atb);
  if (!x.allFinite()) return std::nullopt;
  Affine fit;
  fit.m << x(0), x(1), x(2), x(3);
  fit.t = Point(x(4), x(5));
  if (!(fit.m.determinant() > 0.0)) return std::nullopt;
  return fit;
}

// Group g's outline in drawing d, paired (`p`, any parameterization of it) near an affine image
// of drawing 1's, re-paired through that affine map (ProjectThrough). The map is fitted to `p`'s
// pairing, then refined by affine ICP (point to line, PointToLineStep) on 128 points spread along
// drawing 1's outline and 32 along each of the component's holes (a round outline fits any turn
// of itself; the holes fix it) until the carried outline stops coming nearer (at most
// kAffineRounds); the map where it then carries drawing 1's outline within kAffineMisfit of
// drawing d's, `p` replaced; nothing otherwise. A pairing by features is off the affine one by its
// samples' spacing; the fit to it keeps that bias, the rounds remove it (an affine copy of a
// flame, `scripts/bench correspondence`: its outline carried 0.15% of its length from the copy
// after the first fit, 1e-8 after six rounds; point-to-point ICP gained 0.9x per round).
std::optional<Affine> PairThroughAffine(const GroupedLoops& loops, int g, int d, const Param& p0,
                                        Param* p) {
  constexpr int kAffineRounds = 16;
  constexpr int kOutlinePoints = 128;
  constexpr int kHolePoints = 32;
  const Curve& cd = loops.curve(d, g);
  std::optional<Affine> fit = FitThrough(loops, g, d, p0, *p);
  if (!fit.has_value()) return std::nullopt;
  std::vector<LoopPoints> sets;
  std::vector<int> members = {g};
  for (int h : HoleGroups(loops, g)) members.push_back(h);
  for (int m : members) {
    const Curve& c0 = loops.curve(0, m);
    const int n = m == g ? kOutlinePoints : kHolePoints;
    LoopPoints set{{}, &loops.curve(d, m)};
    for (int k = 0; k < n; ++k) set.from.push_back(c0.At(c0.length() * k / n));
    sets.push_back(std::move(set));
  }
  Affine best = *fit;
  double best_misfit = std::numeric_limits<double>::infinity();
  std::vector<double> misfit;
  for (int round = 0; round < kAffineRounds && fit.has_value(); ++round) {
    std::optional<Affine> next = PointToLineStep(sets, *fit, &misfit);
    const double outline = misfit[0] / cd.length();
    if (round == 0 && !(outline < kAffineMisfit)) return std::nullopt;
    if (!(outline < 0.99 * best_misfit)) break;
    best = *fit, best_misfit = outline;
    fit = next;
  }
  if (!(best_misfit < kAffineMisfit)) return std::nullopt;
  Param projected = ProjectThrough(loops, g, d, best);
  if (projected.t.size() < 3) return std::nullopt;
  *p = std::move(projected);
  return best;
}

// Hole group h in drawing d re-paired through its outline's affine map (PairThroughAffine)
// where that map carries it within kAffineMisfit of drawing d's hole. Not refitted to the hole:
// a round hole fits any turn of itself.
void PairHoleThroughAffine(const GroupedLoops& loops, int h, int d, const Affine& carry, Param* p) {
  if (!(MeanDistanceToLoop(Carried(loops, h, carry), loops.curve(d, h)) < kAffineMisfit)) return;
  Param projected = ProjectThrough(loops, h, d, carry);
  if (projected.t.size() >= 3) *p = std::move(projected);
}

// Outline group g of a component with holes, in drawing d, aligned by features as carried by
// the component's affine map (AlignFeatures) into `p`; false, leaving `p` to arc length from
// the carried start, where that map explains the outline (kCarriedMisfit: it already pairs the
// loops point by point, and an affine map changes the turns the alignment weighs) or where the
// aligned outline does not carry every hole onto its match (OutlineMap, kHoleMisfit). The holes
// follow the outline's correspondence (AlignCarriedHole); one it does not carry onto its match
// would be paired against it, and between unrelated drawings (icon pairs) such pairings build
// maps that fold and fall back to larger overlays (docs/benchmarks.md, "Boundary
// correspondence": aligning those outlines anyway made the icon builds slower).
bool AlignCarriedOutline(const GroupedLoops& loops, int g, int d, double start,
                         double corner_angle_degrees, const Parameterization& param, Param* p) {
  const Affine& carry = *loops.groups.carry[g][d];
  if (CarriedMisfit(loops.curve(0, g), loops.curve(d, g), carry, start) < kCarriedMisfit) {
    return false;
  }
  Param trial;
  trial.length = p->length;
  const Points carried = Carried(loops, g, carry);
  AlignFeatures(loops, g, d, start, corner_angle_degrees, &carried, &trial);
  const OutlineMap map(loops.curve(0, g), param.param[0][g], loops.curve(d, g), trial);
  for (int h : HoleGroups(loops, g)) {
    if (!(MeanDistanceToLoop(Carried(loops, h, map), loops.curve(d, h)) < kHoleMisfit))
      return false;
  }
  *p = std::move(trial);
  return true;
}

// Hole group h in drawing d aligned by features as carried by its outline's correspondence
// (OutlineMap) into `p`, where the outline was aligned or matched by corners and carries the
// hole onto its match (kHoleMisfit); false otherwise (arc length from the carried start).
bool AlignCarriedHole(const GroupedLoops& loops, int h, int d, double start,
                      double corner_angle_degrees, const Parameterization& param, Param* p) {
  const int g = OutlineGroup(loops, h);
  if (!param.aligned[d][g]) return false;
  const OutlineMap map(loops.curve(0, g), param.param[0][g], loops.curve(d, g), param.param[d][g]);
  const Points carried = Carried(loops, h, map);
  if (!(MeanDistanceToLoop(carried, loops.curve(d, h)) < kHoleMisfit)) return false;
  AlignFeatures(loops, h, d, start, corner_angle_degrees, &carried, p);
  return true;
}

// Group g's parameterization in every drawing (out->param[d][g]) and its pinned parameters.
// Without marks: the automatic alignment, and corners matched to corners where every drawing
// has as many on this loop (they then pin the parameterization as marks would, without being
// marks: not pinned in the optimizer, not in mark_vertices).
absl::Status ParameterizeGroup(const GroupedLoops& loops, int g,
                               const BoundaryCorrespondenceOptions& options,
                               Parameterization* out) {
  const int num_shapes = loops.num_shapes();
  std::sort(out->marks[g].begin(), out->marks[g].end());
  std::vector<double> start(num_shapes, 0.0);
  std::vector<ArcPin> corner_pairs;
  if (out->marks[g].empty()) {
    start = AlignedStarts(loops, g);
    if (options.match_corners) {
      std::vector<const Curve*> loop_curves;
      for (int d = 0; d < num_shapes; ++d) loop_curves.push_back(&loops.curve(d, g));
      corner_pairs = MatchCorners(loop_curves, start, options.corner_angle_degrees);
    }
  }
  out->corner_matched_loops += corner_pairs.empty() ? 0 : 1;
  const std::vector<ArcPin>& pins = out->marks[g].empty() ? corner_pairs : out->marks[g];
  const double len0 = loops.curve(0, g).length();
  for (const ArcPin& pin : pins) out->pinned_t[g].push_back((pin.first - pins[0].first) / len0);
  for (int d = 0; d < num_shapes; ++d) {
    Param& p = out->param[d][g];
    p.length = loops.curve(d, g).length();
    const bool carried = loops.groups.carry[g][d].has_value();
    bool align = pins.empty() && d > 0 &&
                 options.alignment == BoundaryCorrespondenceOptions::Alignment::kFeatures;
    const bool features = align;
    if (align && !carried) {
      AlignFeatures(loops, g, d, start[d], options.corner_angle_degrees, nullptr, &p);
    } else if (align && loops.groups.outer[g]) {
      align = AlignCarriedOutline(loops, g, d, start[d], options.corner_angle_degrees, *out, &p);
    } else if (align) {
      align = AlignCarriedHole(loops, g, d, start[d], options.corner_angle_degrees, *out, &p);
    }
    out->aligned[d][g] = align || (d > 0 && !corner_pairs.empty());
    if (!align && pins.empty()) {
      p.t = {0.0};
      p.a = {start[d]};
    } else if (!align) {
      if (absl::Status s = KnotsAtPins(pins, d, len0, &p); !s.ok()) return s;
    }
    // A loop along a cut or an opening keeps its pairing: a part cut from a whole fits the part
    // drawn apart within kAffineMisfit without being its affine image, and the near fit puts the
    // whole's corners a hair off the part's, where they merge (NearBreak) and the whole's
    // boundary edges cut them beside the cut's ends.
    if (!features || loops.groups.seamed[g]) continue;
    if (loops.groups.outer[g]) {
      out->affine[d][g] = PairThroughAffine(loops, g, d, out->param[0][g], &p);
    } else if (const std::optional<Affine>& map = out->affine[d][OutlineGroup(loops, g)]) {
      PairHoleThroughAffine(loops, g, d, *map, &p);
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<Parameterization> ParameterizeGroups(const GroupedLoops& loops,
                                                    const BoundaryCorrespondenceOptions& options) {
  const int num_groups = loops.num_groups();
  Parameterization out;
  out.param.assign(loops.num_shapes(), std::vector<Param>(num_groups));
  out.marks.resize(num_groups);
  out.pinned_t.resize(num_groups);
  out.aligned.assign(loops.num_shapes(), std::vector<bool>(num_groups, false));
  out.affine.assign(loops.num_shapes(), std::vector<std::optional<Affine>>(num_groups));
  for (size_t m = 0; m < options.marks.size(); ++m) {
    absl::StatusOr<PlacedMark> placed =
        PlaceMark(loops, options.marks[m], m, options.corner_angle_degrees);
    if (!placed.ok()) return placed.status();
    out.marks[placed->group].push_back({placed->at[0], placed->at});
    out.mark_at.push_back({placed->group, placed->at[0]});
  }
  for (int g = 0; g < num_groups; ++g) {
    if (absl::Status s = ParameterizeGroup(loops, g, options, &out); !s.ok()) return s;
  }
  return out;
}

}  // namespace inbetween::solver::boundary_internal
