// S-Sec.1 "Boundary Tool" and "Initial Meshing" (compatible reparameterization): loop matching,
// marks or automatic alignment, common breakpoints (marks, corners and cut/opening ends of every
// drawing, mirrored across each cohesive zone), equal vertex counts per segment between them.
#include "solver/geometry/boundary_correspondence.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <string>

#include "absl/strings/str_cat.h"
#include "solver/geometry/affine_fit.h"
#include "solver/geometry/loop_alignment.h"
#include "solver/geometry/polygon.h"
#include "solver/geometry/primitives.h"
#include "solver/geometry/resample_outline.h"

namespace inbetween::solver {
namespace {

constexpr int kDefaultVertices = 64;
constexpr int kAlignSamples = 128;
// Rounds of matching loops again by the affine fit of the matched loops' centroids (each round
// stops early once the match settles; a 30 x 30 grid of parts under a shear settles in 16, and 4
// left most of it paired with neighbours).
constexpr int kMaxHoleRematches = 16;
// Turns of the outline's affine map tried as starts of the hole matching (MatchHoles).
constexpr int kRotationHypotheses = 24;
// Above this many holes only the outline's map itself is refitted (each turn costs a few
// assignments, O(holes^3): a 30 x 30 grid of holes took 16 s with every turn, 0.3 s without).
constexpr size_t kMaxHolesForTurns = 64;
// Holes' centroids spread less than this across their main direction do not fix an affine map.
constexpr double kMinHoleSpread = 0.1;
// Matches from turned maps that score within this factor of the best (plus the scores' sampling
// floor, SamplingFloor) are equally good: of those, the one that turns least from the first
// candidate's map wins (ChooseMatch).
constexpr double kScoreTie = 1.5;
constexpr double kSameT = 1e-9;

double Wrap01(double t) {
  t -= std::floor(t);
  return t >= 1.0 ? 0.0 : t;
}

// A closed polyline with its cumulative arc length.
struct Curve {
  Points p;
  std::vector<double> cum;  // cum[k] = arc length at p[k]; cum[n] = perimeter
  double length() const { return cum.back(); }
  Point At(double u) const { return PointAtArcLength(p, cum, u, SegmentEnds::kExact); }
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

Curve MakeCurve(const Points& p) {
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
    const size_t m = t.size();
    size_t j = std::upper_bound(t.begin(), t.end(), u) - t.begin();
    j = std::max<size_t>(j, 1) - 1;
    const double t1 = j + 1 < m ? t[j + 1] : 1.0;
    const double a1 = j + 1 < m ? a[j + 1] : a[0] + length;
    const double f = t1 > t[j] ? (u - t[j]) / (t1 - t[j]) : 0.0;
    return a[j] + f * (a1 - a[j]);
  }
  double Inverse(double arc) const {
    arc = a[0] + std::fmod(std::fmod(arc - a[0], length) + length, length);
    const size_t m = a.size();
    size_t j = std::upper_bound(a.begin(), a.end(), arc) - a.begin();
    j = std::max<size_t>(j, 1) - 1;
    const double t1 = j + 1 < m ? t[j + 1] : 1.0;
    const double a1 = j + 1 < m ? a[j + 1] : a[0] + length;
    const double f = a1 > a[j] ? (arc - a[j]) / (a1 - a[j]) : 0.0;
    return Wrap01(t[j] + f * (t1 - t[j]));
  }
};

// One side of a cut/opening run of a drawing: arc lengths [a0, a1] on loop `group`, collocated
// with [b0, b1] of `twin_group` walked the other way.
struct Run {
  int group, twin_group;
  double a0, a1, b0, b1;
  // Mirror of arc length x (a0 < x < a1, unwrapped past the loop start if needed).
  double Mirror(double x) const { return b1 - (x - a0); }
};

std::vector<Run> SeamRuns(const BoundaryGraph& g, const std::vector<int>& group_of_loop,
                          const std::vector<Curve>& curves) {
  std::vector<Run> runs;
  for (size_t l = 0; l < g.loops.size(); ++l) {
    const BoundaryLoop& loop = g.loops[l];
    const int n = static_cast<int>(loop.points.size());
    auto continues = [&](int k) {  // edge k+1 continues the run of edge k
      const int k1 = (k + 1) % n;
      const auto [tl, te] = loop.twin[k];
      const auto [ul, ue] = loop.twin[k1];
      if (tl < 0 || ul < 0 || tl != ul) return false;
      if (tl == static_cast<int>(l) && te == k1) return false;  // a tip
      const int m = static_cast<int>(g.loops[tl].points.size());
      return ue == (te + m - 1) % m;
    };
    int start = -1;
    for (int k = 0; k < n && start < 0; ++k) {
      if (loop.twin[k].first >= 0 && !continues((k + n - 1) % n)) start = k;
    }
    if (start < 0) {
      if (loop.twin[0].first < 0) continue;
      start = 0;  // the whole loop is one run (a closed cut)
    }
    for (int i = 0; i < n;) {
      const int k = (start + i) % n;
      if (loop.twin[k].first < 0) {
        ++i;
        continue;
      }
      int count = 1;
      while (i + count < n && continues((k + count - 1) % n)) ++count;
      const int last = (k + count - 1) % n;
      const auto [tl, te_first] = loop.twin[k];
      const int te_last = loop.twin[last].second;
      const Curve& a = curves[l];
      const Curve& b = curves[tl];
      Run r;
      r.group = group_of_loop[l];
      r.twin_group = group_of_loop[tl];
      r.a0 = a.cum[k];
      r.a1 = r.a0;
      for (int c = 0; c < count; ++c) {
        const int e = (k + c) % n;
        r.a1 += a.cum[e + 1] - a.cum[e];
      }
      r.b0 = b.cum[te_last];
      r.b1 = r.b0 + (r.a1 - r.a0);
      (void)te_first;
      runs.push_back(r);
      i += count;
    }
  }
  return runs;
}

Point Centroid(const Points& p) {
  const double area = PolygonSignedArea(p);
  Point lo = p[0], hi = p[0];
  for (const Point& q : p) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  const size_t n = p.size();
  if (std::abs(area) > 1e-9 * (hi - lo).squaredNorm()) {
    Point c = Point::Zero();
    for (size_t i = 0; i < n; ++i) {
      const Point& a = p[i];
      const Point& b = p[(i + 1) % n];
      c += (a + b) * Cross(a, b);
    }
    return c / (6 * area);
  }
  Point c = Point::Zero();
  double total = 0;
  for (size_t i = 0; i < n; ++i) {
    const double len = (p[(i + 1) % n] - p[i]).norm();
    c += len * 0.5 * (p[i] + p[(i + 1) % n]);
    total += len;
  }
  return total > 0 ? Point(c / total) : p[0];
}

// Assignment of `a` items to `b` items (same count) minimising total cost: brute force up to 8
// (ties go to the first permutation in lexicographic order), beyond that the Hungarian method
// (shortest augmenting paths with row and column potentials, O(k^3)), also exact; greedy, row by
// row, if a cost is not finite (coordinates near the double range), where the potentials would
// not be.
std::vector<int> Assign(const std::vector<std::vector<double>>& cost) {
  const int k = static_cast<int>(cost.size());
  std::vector<int> perm(k), best;
  std::iota(perm.begin(), perm.end(), 0);
  bool finite = true;
  for (const std::vector<double>& row : cost) {
    for (const double c : row) finite = finite && std::isfinite(c);
  }
  if (!finite) {
    best.assign(k, -1);
    std::vector<bool> taken(k, false);
    for (int i = 0; i < k; ++i) {
      int pick = -1;
      for (int j = 0; j < k; ++j) {
        if (!taken[j] && (pick < 0 || cost[i][j] < cost[i][pick])) pick = j;
      }
      best[i] = pick, taken[pick] = true;
    }
    return best;
  }
  if (k <= 8) {
    double best_cost = std::numeric_limits<double>::infinity();
    do {
      double c = 0;
      for (int i = 0; i < k; ++i) c += cost[i][perm[i]];
      if (c < best_cost) best_cost = c, best = perm;
    } while (std::next_permutation(perm.begin(), perm.end()));
    return best;
  }
  // Rows 1..k and columns 1..k; column 0 is the virtual start of each augmenting path.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> u(k + 1, 0.0), v(k + 1, 0.0);
  std::vector<int> row_of(k + 1, 0), way(k + 1, 0);  // row_of[j]: the row assigned column j
  for (int i = 1; i <= k; ++i) {
    row_of[0] = i;
    int j0 = 0;
    std::vector<double> slack(k + 1, kInf);
    std::vector<bool> used(k + 1, false);
    do {
      used[j0] = true;
      const int i0 = row_of[j0];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= k; ++j) {
        if (used[j]) continue;
        const double reduced = cost[i0 - 1][j - 1] - u[i0] - v[j];
        if (reduced < slack[j]) slack[j] = reduced, way[j] = j0;
        if (slack[j] < delta) delta = slack[j], j1 = j;
      }
      for (int j = 0; j <= k; ++j) {
        if (used[j]) {
          u[row_of[j]] += delta;
          v[j] -= delta;
        } else {
          slack[j] -= delta;
        }
      }
      j0 = j1;
    } while (row_of[j0] != 0);
    do {  // flip the path's assignments back to its start
      const int j1 = way[j0];
      row_of[j0] = row_of[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  best.assign(k, -1);
  for (int j = 1; j <= k; ++j) best[row_of[j] - 1] = j - 1;
  return best;
}

// Best start (arc length) of `b` against `a` (both normalised): turning angle + position. With
// `carry`, `a` is first carried into b's drawing by that map (and normalised as b).
double AlignStart(const Curve& a, const Curve& b, const Point& ca, double sa, const Point& cb,
                  double sb, const Affine* carry = nullptr) {
  const int m = kAlignSamples;
  Points pa(m), pb(m);
  Points ua(m), ub(m);  // (cos, sin) of the tangents' angles ta, tb
  for (int k = 0; k < m; ++k) {
    pa[k] = carry == nullptr ? Point((a.At(a.length() * k / m) - ca) / sa)
                             : Point((carry->m * a.At(a.length() * k / m) + carry->t - cb) / sb);
    pb[k] = (b.At(b.length() * k / m) - cb) / sb;
  }
  for (int k = 0; k < m; ++k) {
    Point da = a.At(a.length() * (k + 0.5) / m) - a.At(a.length() * (k - 0.5) / m);
    if (carry != nullptr) da = carry->m * da;
    const Point db = b.At(b.length() * (k + 0.5) / m) - b.At(b.length() * (k - 0.5) / m);
    const double ta = std::atan2(da.y(), da.x()), tb = std::atan2(db.y(), db.x());
    ua[k] = Point(std::cos(ta), std::sin(ta));
    ub[k] = Point(std::cos(tb), std::sin(tb));
  }
  Point mean = Point::Zero();
  for (const Point& p : pa) mean += p / m;
  double radius2 = 0;
  for (const Point& p : pa) radius2 += (p - mean).squaredNorm() / m;
  radius2 = std::max(radius2, 1e-12);
  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int s = 0; s < m; ++s) {
    double sn = 0, cs = 0, position = 0;
    for (int k = 0; k < m; ++k) {
      // sin and cos of ta[k] - tb[k + s], by the angle-difference identities (no trigonometry in
      // the m^2 loop: it was most of a many-part drawing's loop matching).
      const Point& u = ua[k];
      const Point& v = ub[(k + s) % m];
      sn += Cross(v, u), cs += u.x() * v.x() + u.y() * v.y();
      position += (pa[k] - pb[(k + s) % m]).squaredNorm();
    }
    // sum_k (1 - cos(d_k - rotation)) at the best rotation = m - |sum e^{i d_k}|.
    const double turning = m - std::hypot(sn, cs);
    const double cost = turning / m + position / (m * radius2);
    if (cost < best_cost) best_cost = cost, best = s;
  }
  return b.length() * best / m;
}

// The affine fit of outline `a` (drawing 1) onto outline `b` (another drawing), the two sampled
// at kAlignSamples equal arc-length steps from their aligned starts (b_start on b).
bool OutlineAffine(const Curve& a, const Curve& b, double b_start, Affine* fit) {
  const int n = kAlignSamples;
  std::vector<std::pair<Point, Point>> pairs;
  for (int k = 0; k < n; ++k) {
    pairs.emplace_back(a.At(a.length() * k / n), b.At(b_start + b.length() * k / n));
  }
  return FitAffine(pairs, fit);
}

// Loops (or components, by their outer loops) of drawing 1 paired by correspondence marks with
// loops of another drawing: to[a] = b and from[b] = a, else -1, with the mark that paired them.
struct Pins {
  std::vector<int> to, from, to_mark, from_mark;
  Pins() = default;
  Pins(size_t loops0, size_t loops)
      : to(loops0, -1), from(loops, -1), to_mark(loops0), from_mark(loops) {}

  // Pairs a with b for mark `mark` (0-based) of drawing d (0-based); INVALID_ARGUMENT naming both
  // marks when an earlier mark paired either with another (`what`: "outline", "hole", "component").
  absl::Status Add(int a, int b, int mark, int d, const char* what) {
    if (to[a] >= 0 && to[a] != b) {
      return absl::InvalidArgumentError(
          absl::StrCat("correspondence marks ", to_mark[a] + 1, " and ", mark + 1, " sit on one ",
                       what, " of drawing 1 but on two different ", what, "s of drawing ", d + 1));
    }
    if (from[b] >= 0 && from[b] != a) {
      return absl::InvalidArgumentError(absl::StrCat(
          "correspondence marks ", from_mark[b] + 1, " and ", mark + 1, " sit on two different ",
          what, "s of drawing 1 but on one ", what, " of drawing ", d + 1));
    }
    to[a] = b, from[b] = a, to_mark[a] = mark, from_mark[b] = mark;
    return absl::OkStatus();
  }
  // Whether pairing drawing 1's loop a with b breaks a pin.
  bool Breaks(int a, int b) const {
    return (!to.empty() && to[a] >= 0 && to[a] != b) ||
           (!from.empty() && from[b] >= 0 && from[b] != a);
  }
};

// Which pairings of drawing 1's loops (rows) with another drawing's (columns) may be made at all
// (components: the same number of holes); empty: all.
using Allowed = std::vector<std::vector<bool>>;

// Makes every pairing of rows[i] (drawing 1's loops) with cols[j] (another drawing's) that
// breaks a pin, or that `allowed` rules out, cost more than all other pairings together, so that
// the exact assignment makes none where it can (Pins::Add keeps the pins consistent).
void Penalize(const Pins& pins, const std::vector<int>& rows, const std::vector<int>& cols,
              const Allowed& allowed, std::vector<std::vector<double>>* cost) {
  double total = 1.0;
  for (const std::vector<double>& row : *cost) {
    for (const double c : row) total += std::abs(c);
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    for (size_t j = 0; j < cols.size(); ++j) {
      if (pins.Breaks(rows[i], cols[j]) || (!allowed.empty() && !allowed[i][j])) {
        (*cost)[i][j] += total;
      }
    }
  }
}

// One drawing's loops as the loop matching sees them: curves, area centroids in the drawing's
// bounding-box normalisation (centre, scale).
struct LoopSet {
  const std::vector<Curve>* curves;
  const std::vector<Point>* centroid;  // normalised
  Point centre;
  double scale;
  Point Raw(int loop) const { return centre + scale * (*centroid)[loop]; }
};

struct HoleMatch {
  std::vector<int> assignment;  // per hole of drawing 1, its match's index in the other's holes
  std::optional<Affine> carry;  // the map that matched them, if any
  double score = std::numeric_limits<double>::infinity();
};

// How far drawing 1's loop `a`, carried, lies from loop `b` of another drawing: the mean squared
// distance over arc-length samples from the aligned starts.
double CarriedDistance(const LoopSet& from, const LoopSet& to, int a, int b, const Affine& carry) {
  const Curve& ca = (*from.curves)[a];
  const Curve& cb = (*to.curves)[b];
  const double b0 = AlignStart(ca, cb, from.centre, from.scale, to.centre, to.scale, &carry);
  const int n = kAlignSamples;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    sum += (carry.m * ca.At(ca.length() * k / n) + carry.t - cb.At(b0 + cb.length() * k / n))
               .squaredNorm();
  }
  return sum / n;
}

// Drawing 1's loops `loops0` matched to another drawing's `loops` from the map `carry`: by the
// carried area centroids, then (with `refit`) the map fitted to the matched centroids (affine
// images of each other in a copy) and the loops matched again, until the match settles. Scored
// by how far the carried loops, and the enclosing outline `outline0` (holes; -1: none) from
// `outline`, lie from their matches (CarriedDistance, summed).
HoleMatch MatchLoopsFrom(const LoopSet& from, const LoopSet& to, int outline0, int outline,
                         const std::vector<int>& loops0, const std::vector<int>& loops,
                         const Pins& pins, const Allowed& allowed, Affine carry, bool refit) {
  HoleMatch out;
  for (int round = 0; round <= kMaxHoleRematches; ++round) {
    std::vector<std::vector<double>> cost(loops0.size(), std::vector<double>(loops.size()));
    for (size_t a = 0; a < loops0.size(); ++a) {
      for (size_t b = 0; b < loops.size(); ++b) {
        cost[a][b] = (carry.m * from.Raw(loops0[a]) + carry.t - to.Raw(loops[b])).squaredNorm();
      }
    }
    Penalize(pins, loops0, loops, allowed, &cost);
    std::vector<int> again = Assign(cost);
    if (again == out.assignment) break;
    out.assignment = std::move(again);
    std::vector<std::pair<Point, Point>> matched;
    for (size_t a = 0; a < loops0.size(); ++a) {
      matched.emplace_back(from.Raw(loops0[a]), to.Raw(loops[out.assignment[a]]));
    }
    Affine fit;
    if (!refit || !FitAffine(matched, &fit)) break;
    carry = fit;
  }
  out.carry = carry;
  out.score = outline0 >= 0 ? CarriedDistance(from, to, outline0, outline, carry) : 0.0;
  for (size_t a = 0; a < loops0.size(); ++a) {
    out.score += CarriedDistance(from, to, loops0[a], loops[out.assignment[a]], carry);
  }
  return out;
}

// The turn (radians, in [-pi, pi]) of an affine map's linear part: the angle of its nearest
// rotation.
double TurnOf(const Affine& a) { return std::atan2(a.m(1, 0) - a.m(0, 1), a.m(0, 0) + a.m(1, 1)); }

// What a match's score (CarriedDistance, summed) may hold of the sampling alone: per loop scored
// in the other drawing, its squared arc-length step between samples. Summed like the scores, so
// that many loops' noise stays within it, but far below what one loop paired with a neighbour
// adds (a floor of a fixed share of the squared diagonal per loop hid that on grids of hundreds
// of holes, and the outline's unrefitted map won there).
double SamplingFloor(const LoopSet& to, const std::vector<int>& loops, int outline) {
  double floor = 0.0;
  auto add = [&](int l) {
    const double step = (*to.curves)[l].length() / kAlignSamples;
    floor += step * step;
  };
  for (const int l : loops) add(l);
  if (outline >= 0) add(outline);
  return floor;
}

// Of matches from turned maps (candidates[0]: the unturned start), the one whose map turns least
// from candidates[0]'s among those scoring at most kScoreTie times the best score plus `floor`.
// A symmetric layout (four equal dots in a square) is fitted as well by a map a quarter turn off
// as by the right one, and the scores then differ by noise alone; the smaller motion is the one
// meant.
HoleMatch ChooseMatch(std::vector<HoleMatch> candidates, double floor) {
  double best = std::numeric_limits<double>::infinity();
  for (const HoleMatch& c : candidates) best = std::min(best, c.score);
  const double start = candidates[0].carry ? TurnOf(*candidates[0].carry) : 0.0;
  size_t pick = 0;
  double pick_turn = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (!(candidates[i].score <= kScoreTie * best + floor)) continue;
    const double turn =
        candidates[i].carry
            ? std::abs(std::remainder(TurnOf(*candidates[i].carry) - start, 2 * std::numbers::pi))
            : 0.0;
    if (turn < pick_turn) pick_turn = turn, pick = i;
  }
  return std::move(candidates[pick]);
}

// Whether points spread in both directions enough for an affine map to be fitted to them: three
// or more, the smaller principal spread at least kMinHoleSpread of the larger (holes in a row
// leave the map across the row to chance).
bool SpreadInTheFlat(const std::vector<Point>& points) {
  if (points.size() < 3) return false;
  Point mean = Point::Zero();
  for (const Point& p : points) mean += p / static_cast<double>(points.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const Point& p : points) cov += (p - mean) * (p - mean).transpose();
  const Eigen::Vector2d eig = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvalues();
  return eig(1) > 0.0 && eig(0) >= kMinHoleSpread * kMinHoleSpread * eig(1);
}

// `first` (the match from the map `start` itself) against the matches from `start` turned about
// `c` by each of kRotationHypotheses steps of the full turn (only unturned above
// kMaxHolesForTurns loops) and refitted to the matched centroids (MatchLoopsFrom): the one
// ChooseMatch picks.
HoleMatch MatchTurned(const LoopSet& from, const LoopSet& to, int outline0, int outline,
                      const std::vector<int>& loops0, const std::vector<int>& loops,
                      const Pins& pins, const Allowed& allowed, const Affine& start, const Point& c,
                      HoleMatch first) {
  std::vector<HoleMatch> candidates;
  candidates.push_back(std::move(first));
  const int turns = loops0.size() <= kMaxHolesForTurns ? kRotationHypotheses : 1;
  for (int j = 0; j < turns; ++j) {
    const double angle = 2.0 * std::numbers::pi * j / kRotationHypotheses;
    const Eigen::Matrix2d r{{std::cos(angle), -std::sin(angle)},
                            {std::sin(angle), std::cos(angle)}};
    // p -> start(c + r (p - c))
    const Affine turned{start.m * r, start.m * (c - r * c) + start.t};
    candidates.push_back(MatchLoopsFrom(from, to, outline0, outline, loops0, loops, pins, allowed,
                                        turned, /*refit=*/true));
  }
  return ChooseMatch(std::move(candidates), SamplingFloor(to, loops, outline));
}

// The holes of drawing 1's component (outline0, holes0) matched to those of its match in another
// drawing (outline, holes). Drawing 1's holes are carried by the least-squares affine map of the
// outline onto its match (so a sheared, rotated copy matches hole to hole where the bounding
// boxes pair neighbours; MatchLoopsFrom). An outline alone may not fix the map (a round one: any
// rotation fits it), so when the holes' centroids spread in both directions (SpreadInTheFlat)
// the map is also refitted to them, starting from the outline's map turned about the outline's
// centroid (MatchTurned, ChooseMatch: of the candidates that score about as well as the best, the
// one turning least from the outline's map). Without a
// map (drawing 1 itself, or a degenerate fit), the centroids are compared in the bounding-box
// normalisation.
HoleMatch MatchHoles(const LoopSet& from, const LoopSet& to, int outline0, int outline,
                     const std::vector<int>& holes0, const std::vector<int>& holes,
                     const Pins& pins, bool fit) {
  const Curve& a = (*from.curves)[outline0];
  const Curve& b = (*to.curves)[outline];
  Affine carry;
  if (fit && !holes0.empty() &&
      OutlineAffine(a, b, AlignStart(a, b, from.centre, from.scale, to.centre, to.scale), &carry)) {
    HoleMatch unturned =
        MatchLoopsFrom(from, to, outline0, outline, holes0, holes, pins, {}, carry, false);
    std::vector<Point> centroids0;
    for (const int h : holes0) centroids0.push_back(from.Raw(h));
    if (!SpreadInTheFlat(centroids0)) return unturned;
    return MatchTurned(from, to, outline0, outline, holes0, holes, pins, {}, carry,
                       from.Raw(outline0), std::move(unturned));
  }
  std::vector<std::vector<double>> cost(holes0.size(), std::vector<double>(holes.size()));
  for (size_t i = 0; i < holes0.size(); ++i) {
    for (size_t j = 0; j < holes.size(); ++j) {
      cost[i][j] = ((*from.centroid)[holes0[i]] - (*to.centroid)[holes[j]]).squaredNorm();
    }
  }
  Penalize(pins, holes0, holes, {}, &cost);
  HoleMatch out;
  out.assignment = Assign(cost);
  return out;
}

// A corner of a loop: its arc length, the sign of its turn (+1 convex, -1 reflex, for a loop
// with the drawing on its left) and the turn's angle (radians, unsigned).
struct Corner {
  double arc;
  int turn;
  double angle;
};

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

std::vector<std::pair<double, std::vector<double>>> MatchCornersAbove(
    const std::vector<const Curve*>& curves, const std::vector<double>& start,
    double corner_angle_degrees);

std::vector<std::pair<double, std::vector<double>>> MatchCorners(
    const std::vector<const Curve*>& curves, const std::vector<double>& start,
    double corner_angle_degrees) {
  for (double degrees : {std::min(kFineCornerDegrees, corner_angle_degrees), kCollinearDegrees,
                         corner_angle_degrees}) {
    auto pairs = MatchCornersAbove(curves, start, degrees);
    if (!pairs.empty()) return pairs;
  }
  return {};
}

std::vector<std::pair<double, std::vector<double>>> MatchCornersAbove(
    const std::vector<const Curve*>& curves, const std::vector<double>& start,
    double corner_angle_degrees) {
  const int num_shapes = static_cast<int>(curves.size());
  const std::vector<Corner> first = CornersOf(*curves[0], corner_angle_degrees);
  const int n = static_cast<int>(first.size());
  if (n == 0) return {};
  std::vector<std::pair<double, std::vector<double>>> pairs(n);
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

// How far `c`'s outline between arc lengths a0 < a1 (unwrapped, a1 - a0 < length) strays from
// the chord between its ends, and the arc of its farthest vertex.
double ChordDeviation(const Curve& c, double a0, double a1, double* farthest) {
  const double length = c.length();
  const Point p = c.At(a0), q = c.At(a1);
  const int n = static_cast<int>(c.p.size());
  double worst = 0.0;
  *farthest = 0.5 * (a0 + a1);
  // The vertices strictly inside (a0, a1), walking from the one after a0.
  const double base = std::floor(a0 / length) * length;
  int k = static_cast<int>(std::upper_bound(c.cum.begin(), c.cum.end(), a0 - base) - c.cum.begin());
  for (int steps = 0; steps < n; ++steps, ++k) {
    const int wrap = k / n, idx = k % n;
    const double arc = base + wrap * length + c.cum[idx];
    if (arc >= a1) break;
    if (arc <= a0) continue;
    const double dist = DistanceToSegment(c.p[idx], p, q);
    if (dist > worst) worst = dist, *farthest = arc;
  }
  return worst;
}

// Common parameters `ts` (increasing, the interval's vertices, ending before `t1`) with points
// added until, in every drawing d, the outline between consecutive vertices (and the last and
// t1) lies within tol[d] of their chord: each chord that strays is split at its drawing's
// farthest vertex (by that drawing's parameterization), else halved. A rounded tip drawn with
// many small turns gets vertices along it, where the corner test (a turn above
// corner_angle_degrees in one step) saw none.
std::vector<double> RefineToTolerance(const std::vector<double>& ts, double t1,
                                      const std::vector<const Curve*>& curves,
                                      const std::vector<const Param*>& params,
                                      const std::vector<double>& tol) {
  std::vector<double> out;
  // Depth-first over the pieces, in order; a piece narrower than kMinPiece in t is left as it is
  // (coincident vertices would follow).
  constexpr double kMinPiece = 1e-7;
  for (size_t k = 0; k < ts.size(); ++k) {
    const double end = k + 1 < ts.size() ? ts[k + 1] : t1;
    std::vector<std::pair<double, double>> stack = {{ts[k], end}};
    while (!stack.empty()) {
      const auto [lo, hi] = stack.back();
      stack.pop_back();
      double split = -1.0;
      for (size_t d = 0; d < curves.size() && split < 0.0; ++d) {
        const double a0 = params[d]->Forward(lo), a1 = params[d]->Forward(hi);
        double far;
        if (ChordDeviation(*curves[d], a0, a1, &far) > tol[d]) {
          const double t = Wrap01(params[d]->Inverse(far));
          // Inverse wraps into [0, 1); the piece may end at 1.
          const double tt = t < lo ? t + 1.0 : t;
          split = tt > lo + kMinPiece && tt < hi - kMinPiece ? tt : 0.5 * (lo + hi);
        }
      }
      if (split < 0.0 || hi - lo < 2 * kMinPiece) {
        out.push_back(lo);
        continue;
      }
      stack.push_back({split, hi});  // after the first half
      stack.push_back({lo, split});
    }
  }
  return out;
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int Find(int x) { return parent[x] == x ? x : parent[x] = Find(parent[x]); }
  void Unite(int a, int b) { parent[Find(a)] = Find(b); }
};

}  // namespace

// How far a correspondence mark may sit from the boundary it pins, relative to the length of
// that boundary loop.
constexpr double kMarkRelativeTolerance = 0.05;
// A mark computed by a program lands a hair off the drawn corner (an SVG written with four
// decimals puts it 5e-5 units, 1e-7 of the diagonal, from an arrow's corner); pinned there it
// splits the boundary next to the corner's own breakpoint into a sliver interval that every
// drawing must repeat, and the mesher then fails on the sliver in another drawing. So a mark
// within this fraction of its drawing's bounding-box diagonal of a corner of the loop
// (FindCorners at corner_angle_degrees) snaps onto that corner, else onto the nearest vertex of
// the loop within it (BoundaryCorrespondenceOptions::marks).
constexpr double kMarkSnapRelative = 1e-5;
// A mark's interval shorter than this fraction of the drawing's diagonal in some drawing (a mark
// beside another breakpoint that it did not snap to) is refused naming the mark: it would reach
// the mesher as a cusp.
constexpr double kMarkSliverRelative = 1e-6;
// Corners of different drawings closer than this fraction of a drawing's diagonal share one
// breakpoint (see the breakpoints below).
constexpr double kCornerMergeRelative = 1e-4;

namespace {

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

// The loop of drawing `graph` that is component c's outline.
int OuterLoopOf(const BoundaryGraph& graph, int c) {
  for (size_t l = 0; l < graph.loops.size(); ++l) {
    if (graph.loops[l].outer && graph.loops[l].component == c) return static_cast<int>(l);
  }
  return -1;
}

// The loops that correspondence marks pair (each mark sits on the nearest loop of each drawing,
// within kMarkRelativeTolerance of its length; a mark off every loop is left to the
// parameterization, which names it), and their components: loop_pins[d] and component_pins[d]
// for d >= 1. INVALID_ARGUMENT for a mark on an outline in one drawing and on a hole in another,
// or two marks that pair one loop or component with two.
absl::Status PinByMarks(const std::vector<BoundaryGraph>& graphs,
                        const std::vector<std::vector<Curve>>& curves,
                        const std::vector<std::vector<Point>>& marks, std::vector<Pins>* loop_pins,
                        std::vector<Pins>* component_pins) {
  const size_t num_shapes = graphs.size();
  loop_pins->assign(num_shapes, Pins());
  component_pins->assign(num_shapes, Pins());
  auto nearest = [&](size_t d, const Point& p) {
    int best = -1;
    double best_dist = std::numeric_limits<double>::infinity();
    for (size_t l = 0; l < curves[d].size(); ++l) {
      double dist;
      curves[d][l].Project(p, &dist);
      if (dist < best_dist) best_dist = dist, best = static_cast<int>(l);
    }
    return best >= 0 && best_dist <= kMarkRelativeTolerance * curves[d][best].length() ? best : -1;
  };
  for (size_t d = 1; d < num_shapes; ++d) {
    (*loop_pins)[d] = Pins(graphs[0].loops.size(), graphs[d].loops.size());
    (*component_pins)[d] = Pins(graphs[0].loops.size(), graphs[d].loops.size());
  }
  for (size_t m = 0; m < marks.size(); ++m) {
    if (marks[m].size() != num_shapes) continue;  // named by the parameterization
    const int a = nearest(0, marks[m][0]);
    if (a < 0) continue;
    const BoundaryLoop& la = graphs[0].loops[a];
    for (size_t d = 1; d < num_shapes; ++d) {
      const int b = nearest(d, marks[m][d]);
      if (b < 0) continue;
      const BoundaryLoop& lb = graphs[d].loops[b];
      const int dd = static_cast<int>(d), mm = static_cast<int>(m);
      if (la.outer != lb.outer) {
        return absl::InvalidArgumentError(absl::StrCat(
            "drawing ", d + 1, ": correspondence mark ", m + 1, " sits on ",
            lb.outer ? "an outline" : "a hole", " but on ", la.outer ? "an outline" : "a hole",
            " in drawing 1 (a mark pairs an outline with an outline, a hole with a hole)"));
      }
      if (absl::Status s = (*loop_pins)[d].Add(a, b, mm, dd, la.outer ? "outline" : "hole");
          !s.ok()) {
        return s;
      }
      if (absl::Status s =
              (*component_pins)[d].Add(OuterLoopOf(graphs[0], la.component),
                                       OuterLoopOf(graphs[d], lb.component), mm, dd, "component");
          !s.ok()) {
        return s;
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status CheckSameEquivalence(const std::vector<BoundaryGraph>& graphs) {
  bool same = true;
  for (const BoundaryGraph& g : graphs) same = same && g.equivalence == graphs[0].equivalence;
  if (same) return absl::OkStatus();
  std::string message;
  for (size_t d = 0; d < graphs.size(); ++d) {
    absl::StrAppend(&message, d ? "; " : "", "drawing ", d + 1, ": ",
                    graphs[d].equivalence.ToString());
  }
  absl::StrAppend(&message,
                  " — the drawings must have the same topology: add an opening (a slit that "
                  "becomes a hole) where a drawing has fewer holes, or a cut where it has fewer "
                  "components");
  return absl::InvalidArgumentError(message);
}

absl::StatusOr<BoundaryCorrespondence> ComputeBoundaryCorrespondence(
    const std::vector<BoundaryGraph>& graphs, const BoundaryCorrespondenceOptions& options) {
  const int num_shapes = static_cast<int>(graphs.size());
  if (num_shapes == 0) return absl::InvalidArgumentError("no drawings");
  if (absl::Status s = CheckSameEquivalence(graphs); !s.ok()) return s;

  // Normalisation and centroids.
  std::vector<Point> centre(num_shapes);
  std::vector<double> scale(num_shapes);
  std::vector<std::vector<Point>> centroid(num_shapes);
  std::vector<std::vector<Curve>> curves(num_shapes);
  for (int d = 0; d < num_shapes; ++d) {
    Point lo = graphs[d].loops[0].points[0], hi = lo;
    for (const BoundaryLoop& l : graphs[d].loops) {
      for (const Point& p : l.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
    centre[d] = 0.5 * (lo + hi);
    scale[d] = std::max((hi - lo).norm(), 1e-300);
    for (const BoundaryLoop& l : graphs[d].loops) {
      centroid[d].push_back((Centroid(l.points) - centre[d]) / scale[d]);
      curves[d].push_back(MakeCurve(l.points));
    }
  }

  // Correspondence marks decide which loops and components pair where they sit on them.
  std::vector<Pins> loop_pins, component_pins;
  if (absl::Status s = PinByMarks(graphs, curves, options.marks, &loop_pins, &component_pins);
      !s.ok()) {
    return s;
  }

  // Loop groups: drawing 1's components in order, each followed by its holes.
  std::vector<std::vector<int>> group_loops;  // [g][d]
  auto loops_of = [&](int d, int component, bool outer) {
    std::vector<int> out;
    for (size_t l = 0; l < graphs[d].loops.size(); ++l) {
      const BoundaryLoop& loop = graphs[d].loops[l];
      if (loop.outer == outer && (outer || loop.component == component)) {
        out.push_back(static_cast<int>(l));
      }
    }
    return out;
  };
  const std::vector<int> outer0 = loops_of(0, 0, true);
  std::vector<std::vector<int>> component_match(num_shapes);  // [d][c0] -> outer loop in d
  const LoopSet from0{&curves[0], &centroid[0], centre[0], scale[0]};
  std::vector<Point> centroids0;  // drawing 1's components, as drawn
  for (const int l : outer0) centroids0.push_back(from0.Raw(l));
  for (int d = 0; d < num_shapes; ++d) {
    const std::vector<int> outer = loops_of(d, 0, true);
    Allowed same_holes(outer0.size(), std::vector<bool>(outer.size()));
    std::vector<std::vector<double>> cost(outer0.size(), std::vector<double>(outer.size()));
    for (size_t i = 0; i < outer0.size(); ++i) {
      const int h0 =
          static_cast<int>(loops_of(0, graphs[0].loops[outer0[i]].component, false).size());
      for (size_t j = 0; j < outer.size(); ++j) {
        const int hd =
            static_cast<int>(loops_of(d, graphs[d].loops[outer[j]].component, false).size());
        same_holes[i][j] = h0 == hd;
        cost[i][j] =
            (centroid[0][outer0[i]] - centroid[d][outer[j]]).squaredNorm() + (h0 != hd ? 1e6 : 0.0);
      }
    }
    Penalize(component_pins[d], outer0, outer, {}, &cost);
    std::vector<int> assignment = Assign(cost);
    if (d > 0 && SpreadInTheFlat(centroids0)) {
      // Components spread across the drawing: drawing 1's placement in drawing d's bounding box
      // (the match above) against that placement turned about drawing 1's centre and refitted
      // (MatchTurned): a rearranged drawing (a turned copy) pairs each part with its image, not
      // with whichever part now sits where it sat.
      const LoopSet to{&curves[d], &centroid[d], centre[d], scale[d]};
      const double s = scale[d] / scale[0];
      const Affine place{s * Eigen::Matrix2d::Identity(), centre[d] - s * centre[0]};
      HoleMatch placed;  // the placement's own match (above), scored under `place`
      placed.assignment = assignment;
      placed.carry = place;
      placed.score = 0.0;
      for (size_t i = 0; i < outer0.size(); ++i) {
        placed.score += CarriedDistance(from0, to, outer0[i], outer[assignment[i]], place);
      }
      assignment = MatchTurned(from0, to, -1, -1, outer0, outer, component_pins[d], same_holes,
                               place, centre[0], std::move(placed))
                       .assignment;
    }
    for (size_t i = 0; i < outer0.size(); ++i) component_match[d].push_back(outer[assignment[i]]);
  }
  BoundaryCorrespondence out;
  // Per loop group and drawing: the affine map of the component that carried its holes (none
  // without holes, for drawing 1, or a degenerate fit), which aligns the loops' starts.
  std::vector<std::vector<std::optional<Affine>>> hole_carry;
  for (size_t i = 0; i < outer0.size(); ++i) {
    std::vector<int> g(num_shapes);
    for (int d = 0; d < num_shapes; ++d) g[d] = component_match[d][i];
    group_loops.push_back(g);
    out.loop_outer.push_back(true);
    out.loop_component.push_back(static_cast<int>(i));
    const size_t outer_group = hole_carry.size();
    hole_carry.emplace_back(num_shapes);
    std::vector<std::vector<int>> holes(num_shapes);
    for (int d = 0; d < num_shapes; ++d) {
      holes[d] = loops_of(d, graphs[d].loops[g[d]].component, false);
      if (holes[d].size() != holes[0].size()) {
        return absl::InvalidArgumentError(
            absl::StrCat("drawing ", d + 1, ": the component matched to drawing 1's component ",
                         i + 1, " has ", holes[d].size(), " holes instead of ", holes[0].size()));
      }
    }
    // Holes: drawing 1's holes carried by an affine map of the component (MatchHoles), else (a
    // degenerate fit) compared in the bounding-box normalisation. The map aligns each hole's
    // start below.
    std::vector<std::vector<int>> hole_match(num_shapes);
    std::vector<std::optional<Affine>> carry(num_shapes);
    for (int d = 0; d < num_shapes; ++d) {
      const LoopSet to{&curves[d], &centroid[d], centre[d], scale[d]};
      HoleMatch match = MatchHoles(from0, to, g[0], g[d], holes[0], holes[d], loop_pins[d], d > 0);
      carry[d] = match.carry;
      for (size_t a = 0; a < holes[0].size(); ++a) {
        hole_match[d].push_back(holes[d][match.assignment[a]]);
      }
    }
    hole_carry[outer_group] = carry;  // the outline's start too: a round one has no other
    for (size_t a = 0; a < holes[0].size(); ++a) {
      std::vector<int> hg(num_shapes);
      for (int d = 0; d < num_shapes; ++d) hg[d] = hole_match[d][a];
      group_loops.push_back(hg);
      out.loop_outer.push_back(false);
      out.loop_component.push_back(static_cast<int>(i));
      hole_carry.push_back(carry);
    }
  }
  const int num_groups = static_cast<int>(group_loops.size());
  std::vector<std::vector<int>> group_of_loop(num_shapes);
  for (int d = 0; d < num_shapes; ++d) {
    group_of_loop[d].assign(graphs[d].loops.size(), -1);
    for (int g = 0; g < num_groups; ++g) group_of_loop[d][group_loops[g][d]] = g;
  }
  auto curve = [&](int d, int g) -> const Curve& { return curves[d][group_loops[g][d]]; };

  // Parameterizations: marks, else automatic alignment.
  std::vector<std::vector<Param>> param(num_shapes, std::vector<Param>(num_groups));
  std::vector<std::vector<std::pair<double, std::vector<double>>>> marks_on(num_groups);
  std::vector<std::pair<int, double>> mark_at;  // per mark: its loop group, arc in drawing 1
  // Per group: the common parameters that marks (or matched corners) pin, each a breakpoint.
  std::vector<std::vector<double>> pinned_t(num_groups);
  for (size_t m = 0; m < options.marks.size(); ++m) {
    if (static_cast<int>(options.marks[m].size()) != num_shapes) {
      return absl::InvalidArgumentError(absl::StrCat("mark ", m + 1, " has ",
                                                     options.marks[m].size(), " points for ",
                                                     num_shapes, " drawings"));
    }
    int group = -1;
    double best = std::numeric_limits<double>::infinity(), at0 = 0;
    for (int g = 0; g < num_groups; ++g) {
      double dist;
      const double a = curve(0, g).Project(options.marks[m][0], &dist);
      if (dist < best) best = dist, group = g, at0 = a;
    }
    std::vector<double> at(num_shapes, at0);
    for (int d = 0; d < num_shapes; ++d) {
      double dist = best;
      if (d > 0) at[d] = curve(d, group).Project(options.marks[m][d], &dist);
      at[d] = SnapMark(curve(d, group), at[d], kMarkSnapRelative * scale[d],
                       options.corner_angle_degrees);
      // A mark must sit on (near) a boundary; one far away is a mistake, not a pin.
      if (!(dist <= kMarkRelativeTolerance * curve(d, group).length())) {
        const Point& p = options.marks[m][d];
        return absl::InvalidArgumentError(
            absl::StrCat("drawing ", d + 1, ": correspondence mark ", m + 1, " at (", p.x(), ", ",
                         p.y(), ") is ", dist, " from the nearest boundary, more than ",
                         kMarkRelativeTolerance * 100, "% of that boundary's length"));
      }
    }
    marks_on[group].push_back({at[0], at});
    mark_at.push_back({group, at[0]});
  }
  for (int g = 0; g < num_groups; ++g) {
    std::sort(marks_on[g].begin(), marks_on[g].end());
    // Without marks: the automatic alignment, and corners matched to corners where every drawing
    // has as many on this loop (they then pin the parameterization as marks would, without
    // being marks: not pinned in the optimizer, not in mark_vertices).
    std::vector<double> start(num_shapes, 0.0);
    std::vector<std::pair<double, std::vector<double>>> corner_pairs;
    if (marks_on[g].empty()) {
      std::vector<const Curve*> loop_curves;
      for (int d = 0; d < num_shapes; ++d) {
        loop_curves.push_back(&curve(d, g));
        if (d > 0) {
          const std::optional<Affine>& carry = hole_carry[g][d];
          start[d] = AlignStart(curve(0, g), curve(d, g), centre[0], scale[0], centre[d], scale[d],
                                carry.has_value() ? &*carry : nullptr);
        }
      }
      if (options.match_corners) {
        corner_pairs = MatchCorners(loop_curves, start, options.corner_angle_degrees);
      }
    }
    out.corner_matched_loops += corner_pairs.empty() ? 0 : 1;
    const auto& marks = marks_on[g].empty() ? corner_pairs : marks_on[g];
    for (const auto& mark : marks) {
      pinned_t[g].push_back((mark.first - marks[0].first) / curve(0, g).length());
    }
    for (int d = 0; d < num_shapes; ++d) {
      Param& p = param[d][g];
      p.length = curve(d, g).length();
      // A loop that its component's affine map carried (components with holes, MatchHoles)
      // keeps arc length from the carried start: that map already pairs the loops point by
      // point, and an affine map changes the turns the alignment weighs (a sheared flower's
      // outline: arc length 0.5-0.7 units off the affine correspondence, the alignment
      // 1.4-2.8).
      if (marks.empty() && d > 0 && !hole_carry[g][d].has_value() &&
          options.alignment == BoundaryCorrespondenceOptions::Alignment::kFeatures) {
        // Both loops in their drawings' normalised frames, for the alignment's position term.
        Points a = curve(0, g).p, b = curve(d, g).p;
        for (Point& q : a) q = (q - centre[0]) / scale[0];
        for (Point& q : b) q = (q - centre[d]) / scale[d];
        LoopAlignmentOptions align;
        align.corner_angle_degrees = options.corner_angle_degrees;
        const LoopAlignment al = AlignLoops(a, b, start[d] / p.length, align);
        for (size_t k = 0; k < al.a.size(); ++k) {
          p.t.push_back(al.a[k]);
          p.a.push_back(al.b[k] * p.length);
        }
        continue;
      }
      if (marks.empty()) {
        p.t = {0.0};
        p.a = {start[d]};
        continue;
      }
      const double len0 = curve(0, g).length();
      const double base0 = marks[0].first, based = marks[0].second[d];
      for (size_t j = 0; j < marks.size(); ++j) {
        double a = marks[j].second[d] - based;
        a = std::fmod(a + p.length, p.length);
        if (j > 0 && !(a > p.a.back() - based)) {
          return absl::InvalidArgumentError(
              absl::StrCat("drawing ", d + 1,
                           ": correspondence marks on one boundary are not in the same "
                           "order as in drawing 1 (or two marks coincide)"));
        }
        p.t.push_back((marks[j].first - base0) / len0);
        p.a.push_back(based + a);
      }
    }
  }

  // Seam runs per drawing.
  std::vector<std::vector<Run>> runs(num_shapes);
  for (int d = 0; d < num_shapes; ++d) runs[d] = SeamRuns(graphs[d], group_of_loop[d], curves[d]);

  // Breakpoints (common parameter) per group.
  std::vector<std::vector<double>> breaks(num_groups);
  auto add_break = [&](int g, double t) {
    t = Wrap01(t);
    std::vector<double>& b = breaks[g];
    auto it = std::lower_bound(b.begin(), b.end(), t);
    const bool near_next = it != b.end() && *it - t < kSameT;
    const bool near_prev = it != b.begin() && t - *(it - 1) < kSameT;
    const bool near_wrap = !b.empty() && (t + 1 - b.back() < kSameT || b.front() + 1 - t < kSameT);
    if (near_next || near_prev || near_wrap) return false;
    b.insert(it, t);
    return true;
  };
  for (int g = 0; g < num_groups; ++g) {
    breaks[g].push_back(0.0);
    for (int d = 0; d < num_shapes; ++d) {
      if (d == 0) {
        for (double t : pinned_t[g]) add_break(g, t);
      }
      const Curve& c = curve(d, g);
      for (int k : FindCorners(c.p, options.corner_angle_degrees)) {
        const double t = Wrap01(param[d][g].Inverse(c.cum[k]));
        // Two drawings' corners that the correspondence puts a hair apart would make a sliver
        // interval that every drawing repeats (the mesher refuses it as a cusp): a corner within
        // kCornerMergeRelative of an existing breakpoint in some drawing is left to it. Its
        // drawing's vertex then sits that close to the corner, far inside the outline tolerance.
        bool near = false;
        const std::vector<double>& b = breaks[g];
        auto it = std::lower_bound(b.begin(), b.end(), t);
        for (double other : {it != b.end() ? *it : b.front() + 1.0,
                             it != b.begin() ? *(it - 1) : b.back() - 1.0}) {
          for (int e = 0; e < num_shapes && !near; ++e) {
            const Param& p = param[e][g];
            const double gap = std::abs(p.Forward(Wrap01(t)) - p.Forward(Wrap01(other)));
            near = std::min(gap, p.length - gap) < kCornerMergeRelative * scale[e];
          }
        }
        if (!near) add_break(g, t);
      }
    }
  }
  for (int d = 0; d < num_shapes; ++d) {
    for (const Run& r : runs[d]) {
      add_break(r.group, param[d][r.group].Inverse(r.a0));
      add_break(r.group, param[d][r.group].Inverse(r.a1));
    }
  }
  // Where the two sides of a run must agree: mirror every breakpoint inside a run.
  auto inside_run = [&](const Run& r, const Param& p, double t, double* arc) {
    double a = p.Forward(t);
    while (a < r.a0) a += p.length;
    while (a >= r.a0 + p.length) a -= p.length;
    *arc = a;
    const double eps = 1e-9 * p.length;
    return a > r.a0 + eps && a < r.a1 - eps;
  };
  // Cuts of several drawings along the same stretch of boundary agree only where their ends sit
  // at the same common parameter (marks at both ends, or identical geometry between marks);
  // otherwise each mirror adds points the other mirrors again, without end. Bounded: beyond
  // kMaxMirrorGrowth times the breakpoints before mirroring (and at least kMinMirrorBreaks in
  // all) the drawings are refused with what to do, before the correspondence takes minutes and
  // the mesh explodes.
  constexpr int kMaxMirrorGrowth = 8, kMinMirrorBreaks = 4096;
  size_t primary_breaks = 0;
  for (const std::vector<double>& b : breaks) primary_breaks += b.size();
  const size_t max_breaks = std::max<size_t>(kMinMirrorBreaks, kMaxMirrorGrowth * primary_breaks);
  for (int round = 0; round < 16; ++round) {
    bool added = false;
    for (int d = 0; d < num_shapes; ++d) {
      for (const Run& r : runs[d]) {
        const std::vector<double> current = breaks[r.group];
        for (double t : current) {
          double a;
          if (!inside_run(r, param[d][r.group], t, &a)) continue;
          added |= add_break(r.twin_group, param[d][r.twin_group].Inverse(r.Mirror(a)));
        }
      }
    }
    if (!added) break;
    size_t total = 0;
    for (const std::vector<double>& b : breaks) total += b.size();
    if (total > max_breaks) {
      std::string with_cuts;
      int listed = 0;
      for (int d = 0; d < num_shapes; ++d) {
        if (runs[d].empty()) continue;
        if (listed++ < 6) absl::StrAppend(&with_cuts, listed > 1 ? ", " : "", d + 1);
      }
      if (listed > 6) absl::StrAppend(&with_cuts, ", ...");
      return absl::InvalidArgumentError(absl::StrCat(
          "the cuts or openings of drawings ", with_cuts,
          " run along the same boundary but end at different places relative to the "
          "correspondence marks, so their two sides cannot share one set of boundary vertices; "
          "pin both ends of every cut with a correspondence mark (data-corr) in every drawing, "
          "or mark the corners around them"));
    }
  }

  // A mark beside another breakpoint (kMarkSliverRelative) is named here rather than left to
  // fail in the mesher as a cusp of some drawing.
  for (size_t m = 0; m < mark_at.size(); ++m) {
    const auto [g, at0] = mark_at[m];
    const std::vector<double>& b = breaks[g];
    if (b.size() < 2) continue;
    const double t = Wrap01((at0 - marks_on[g][0].first) / curve(0, g).length());
    size_t i = 0;
    double best = 2.0;
    for (size_t j = 0; j < b.size(); ++j) {
      const double gap = std::abs(b[j] - t);
      if (std::min(gap, 1.0 - gap) < best) best = std::min(gap, 1.0 - gap), i = j;
    }
    const double t_prev = i > 0 ? b[i - 1] : b.back() - 1.0;
    const double t_next = i + 1 < b.size() ? b[i + 1] : b[0] + 1.0;
    for (int d = 0; d < num_shapes; ++d) {
      const Param& p = param[d][g];
      const double here = p.Forward(b[i]);
      const double before =
          here - (t_prev < 0 ? p.Forward(t_prev + 1.0) - p.length : p.Forward(t_prev));
      const double after =
          (t_next > 1.0 ? p.Forward(t_next - 1.0) + p.length : p.Forward(t_next)) - here;
      const double shortest = std::min(before, after);
      if (shortest < kMarkSliverRelative * scale[d]) {
        const Point at = curve(d, g).At(here);
        return absl::InvalidArgumentError(absl::StrCat(
            "drawing ", d + 1, ": correspondence mark ", m + 1, " at (", at.x(), ", ", at.y(),
            ") sits ", shortest,
            " from another breakpoint of its boundary (a corner of some "
            "drawing or another mark), too close to keep apart; move the mark onto that corner "
            "or away from it"));
      }
    }
  }

  // Intervals, their twins and vertex counts.
  std::vector<int> interval_start(num_groups + 1, 0);
  for (int g = 0; g < num_groups; ++g) {
    interval_start[g + 1] = interval_start[g] + static_cast<int>(breaks[g].size());
  }
  const int num_intervals = interval_start.back();
  auto interval_end_t = [&](int g, int i) {
    return i + 1 < static_cast<int>(breaks[g].size()) ? breaks[g][i + 1] : breaks[g][0] + 1.0;
  };
  auto interval_of = [&](int g, double t) {
    t = Wrap01(t);
    const std::vector<double>& b = breaks[g];
    int i = static_cast<int>(std::upper_bound(b.begin(), b.end(), t) - b.begin()) - 1;
    return i < 0 ? static_cast<int>(b.size()) - 1 : i;
  };
  // twin_interval[d][global interval] = global twin interval in drawing d or -1.
  std::vector<std::vector<int>> twin_interval(num_shapes, std::vector<int>(num_intervals, -1));
  UnionFind classes(num_intervals);
  for (int d = 0; d < num_shapes; ++d) {
    for (const Run& r : runs[d]) {
      for (int i = 0; i < static_cast<int>(breaks[r.group].size()); ++i) {
        const double mid = 0.5 * (breaks[r.group][i] + interval_end_t(r.group, i));
        double a;
        if (!inside_run(r, param[d][r.group], mid, &a)) continue;
        const int j = interval_of(r.twin_group, param[d][r.twin_group].Inverse(r.Mirror(a)));
        const int gi = interval_start[r.group] + i, gj = interval_start[r.twin_group] + j;
        twin_interval[d][gi] = gj;
        twin_interval[d][gj] = gi;
        classes.Unite(gi, gj);
      }
    }
  }
  int total_corners = 0;
  for (int g = 0; g < num_groups; ++g) total_corners += static_cast<int>(breaks[g].size());
  const int budget =
      options.vertices > 0 ? options.vertices : std::max(kDefaultVertices, 2 * total_corners);
  std::vector<double> spacing(num_shapes);
  for (int d = 0; d < num_shapes; ++d) {
    double perimeter = 0;
    for (int g = 0; g < num_groups; ++g) perimeter += curve(d, g).length();
    spacing[d] = perimeter / budget;
  }
  std::vector<int> count(num_intervals, 1);
  for (int g = 0; g < num_groups; ++g) {
    const int m = static_cast<int>(breaks[g].size());
    const int minimum = m == 1 ? 4 : m <= 3 ? 2 : 1;
    for (int i = 0; i < m; ++i) {
      int c = minimum;
      for (int d = 0; d < num_shapes; ++d) {
        const double len =
            param[d][g].Forward(interval_end_t(g, i)) - param[d][g].Forward(breaks[g][i]);
        c = std::max(c, static_cast<int>(std::lround(len / spacing[d])));
      }
      count[interval_start[g] + i] = c;
    }
  }
  std::vector<int> class_count(num_intervals, 0);
  for (int i = 0; i < num_intervals; ++i) {
    class_count[classes.Find(i)] = std::max(class_count[classes.Find(i)], count[i]);
  }
  for (int i = 0; i < num_intervals; ++i) count[i] = class_count[classes.Find(i)];

  // Each interval's vertices as common parameters: `count` evenly spaced, then (with a
  // tolerance, and no fixed vertex count) refined until every drawing's polyline lies within the
  // tolerance of its outline (RefineToTolerance). Intervals of a cut or opening keep the even
  // spacing, which their twins repeat.
  std::vector<std::vector<double>> interval_t(num_intervals);
  std::vector<bool> has_twin(num_intervals, false);
  for (int d = 0; d < num_shapes; ++d) {
    for (int i = 0; i < num_intervals; ++i) has_twin[i] = has_twin[i] || twin_interval[d][i] >= 0;
  }
  const bool refine = options.tolerance > 0.0 && options.vertices <= 0;
  for (int i = 0; i < num_intervals; ++i) out.base_vertices += count[i];
  for (int g = 0; g < num_groups; ++g) {
    for (int i = 0; i < static_cast<int>(breaks[g].size()); ++i) {
      const int gi = interval_start[g] + i;
      const double t0 = breaks[g][i], t1 = interval_end_t(g, i);
      std::vector<double>& ts = interval_t[gi];
      for (int k = 0; k < count[gi]; ++k) ts.push_back(t0 + (t1 - t0) * k / count[gi]);
      if (!refine || has_twin[gi]) continue;
      std::vector<const Curve*> cs;
      std::vector<const Param*> ps;
      std::vector<double> tol;
      for (int d = 0; d < num_shapes; ++d) {
        cs.push_back(&curve(d, g)), ps.push_back(&param[d][g]);
        tol.push_back(options.tolerance * scale[d]);
      }
      ts = RefineToTolerance(ts, t1, cs, ps, tol);
      count[gi] = static_cast<int>(ts.size());
    }
  }

  // Vertex numbering and sampling.
  std::vector<int> first_vertex(num_intervals + 1, 0);
  for (int i = 0; i < num_intervals; ++i) first_vertex[i + 1] = first_vertex[i] + count[i];
  out.loop_start.resize(num_groups + 1);
  for (int g = 0; g <= num_groups; ++g) out.loop_start[g] = first_vertex[interval_start[g]];
  const int num_vertices = first_vertex.back();
  out.shapes.assign(num_shapes, std::vector<Points>(num_groups));
  out.edge_twin.assign(num_shapes, std::vector<int>(num_vertices, -1));
  for (int d = 0; d < num_shapes; ++d) {
    Points flat(num_vertices);
    for (int g = 0; g < num_groups; ++g) {
      for (int i = 0; i < static_cast<int>(breaks[g].size()); ++i) {
        const int gi = interval_start[g] + i;
        // Uniform in the common parameter, through the drawing's parameterization: arc length
        // between breakpoints where that is linear (marks), the alignment's map otherwise.
        const double t1 = interval_end_t(g, i);
        for (int k = 0; k < count[gi]; ++k) {
          const double a0 = param[d][g].Forward(interval_t[gi][k]);
          flat[first_vertex[gi] + k] = curve(d, g).At(a0);
          const double a1 = param[d][g].Forward(k + 1 < count[gi] ? interval_t[gi][k + 1] : t1);
          double far;
          out.achieved_tolerance = std::max(out.achieved_tolerance,
                                            ChordDeviation(curve(d, g), a0, a1, &far) / scale[d]);
        }
      }
    }
    // Collocate the two sides of each cut/opening of drawing d exactly, and pair their edges.
    auto next_in_loop = [&](int gi) {  // the interval after gi in its loop
      int g = static_cast<int>(std::upper_bound(interval_start.begin(), interval_start.end(), gi) -
                               interval_start.begin()) -
              1;
      return gi + 1 < interval_start[g + 1] ? gi + 1 : interval_start[g];
    };
    for (int gi = 0; gi < num_intervals; ++gi) {
      const int gj = twin_interval[d][gi];
      if (gj < 0) continue;
      const int n = count[gi];
      for (int k = 0; k < n; ++k) {
        out.edge_twin[d][first_vertex[gi] + k] = first_vertex[gj] + (n - 1 - k);
      }
      if (gi > gj) continue;  // copy positions from the lower interval
      for (int k = 1; k < n; ++k) flat[first_vertex[gj] + (n - k)] = flat[first_vertex[gi] + k];
      flat[first_vertex[next_in_loop(gj)]] = flat[first_vertex[gi]];
      flat[first_vertex[gj]] = flat[first_vertex[next_in_loop(gi)]];
    }
    for (int g = 0; g < num_groups; ++g) {
      out.shapes[d][g].assign(flat.begin() + out.loop_start[g],
                              flat.begin() + out.loop_start[g + 1]);
    }
  }
  // Each mark's breakpoint (the nearest one: add_break kept an earlier breakpoint within kSameT
  // instead of a second one) starts an interval; its first vertex is the mark's.
  for (int g = 0; g < num_groups; ++g) {
    const std::vector<double>& b = breaks[g];
    for (const auto& [at0, unused] : marks_on[g]) {
      const double t = Wrap01((at0 - marks_on[g][0].first) / curve(0, g).length());
      int nearest = 0;
      double best = 2.0;
      for (size_t i = 0; i < b.size(); ++i) {
        const double gap = std::abs(b[i] - t);
        const double dist = std::min(gap, 1.0 - gap);
        if (dist < best) best = dist, nearest = static_cast<int>(i);
      }
      out.mark_vertices.push_back(first_vertex[interval_start[g] + nearest]);
    }
  }
  std::sort(out.mark_vertices.begin(), out.mark_vertices.end());
  out.mark_vertices.erase(std::unique(out.mark_vertices.begin(), out.mark_vertices.end()),
                          out.mark_vertices.end());
  return out;
}

}  // namespace inbetween::solver
