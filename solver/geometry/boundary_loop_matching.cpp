// Loop matching for ComputeBoundaryCorrespondence (boundary_correspondence.h, the comment above
// BoundaryCorrespondence): correspondence marks pin loop and component pairs; components are then
// matched by their normalised area centroids (and, spread across the drawing, by turned and
// refitted affine maps of the placement), holes by their centroids carried by the affine map of
// their component's outline (refitted from turns of it where the holes spread across).
// Assignments are exact (brute force up to 8, the Hungarian method beyond).
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
#include "solver/geometry/boundary_correspondence_internal.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver::boundary_internal {
namespace {

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

// The area centroid of a closed polygon; of its edges (by length) when its area vanishes (a slit).
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

using CostMatrix = std::vector<std::vector<double>>;

// Row by row, each row's cheapest column not yet taken (the first of equals).
std::vector<int> AssignGreedy(const CostMatrix& cost) {
  const int k = static_cast<int>(cost.size());
  std::vector<int> best(k, -1);
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

// Every permutation; ties go to the first in lexicographic order.
std::vector<int> AssignBruteForce(const CostMatrix& cost) {
  const int k = static_cast<int>(cost.size());
  std::vector<int> perm(k), best;
  std::iota(perm.begin(), perm.end(), 0);
  double best_cost = std::numeric_limits<double>::infinity();
  do {
    double c = 0;
    for (int i = 0; i < k; ++i) c += cost[i][perm[i]];
    if (c < best_cost) best_cost = c, best = perm;
  } while (std::next_permutation(perm.begin(), perm.end()));
  return best;
}

// The Hungarian method: shortest augmenting paths with row and column potentials, O(k^3).
std::vector<int> AssignHungarian(const CostMatrix& cost) {
  const int k = static_cast<int>(cost.size());
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
  std::vector<int> best(k, -1);
  for (int j = 1; j <= k; ++j) best[row_of[j] - 1] = j - 1;
  return best;
}

// Assignment of `a` items to `b` items (same count) minimising total cost: brute force up to 8,
// beyond that the Hungarian method, also exact; greedy, row by row, if a cost is not finite
// (coordinates near the double range), where the potentials would not be.
std::vector<int> Assign(const CostMatrix& cost) {
  bool finite = true;
  for (const std::vector<double>& row : cost) {
    for (const double c : row) finite = finite && std::isfinite(c);
  }
  if (!finite) return AssignGreedy(cost);
  if (cost.size() <= 8) return AssignBruteForce(cost);
  return AssignHungarian(cost);
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

// One matching of drawing 1's loops `loops0` with another drawing's `loops`: the holes of
// outlines `outline0` and `outline`, or components (both -1). Pairings that break a pin, or that
// `allowed` rules out, are made only where no other assignment is left (Penalize).
struct MatchProblem {
  const LoopSet& from;
  const LoopSet& to;
  int outline0;
  int outline;
  const std::vector<int>& loops0;
  const std::vector<int>& loops;
  const Pins& pins;
  const Allowed& allowed;
};

// The map MatchLoopsFrom starts from, and whether it refits the map to each match.
struct StartMap {
  Affine carry;
  // Refit the map to the matched centroids and match again until the match settles (at most
  // kMaxHoleRematches rounds); false: the one match of `carry`.
  bool refit = false;
};

// The exact assignment of the problem's loops by their area centroids, drawing 1's carried.
std::vector<int> AssignCarried(const MatchProblem& problem, const Affine& carry) {
  const std::vector<int>& loops0 = problem.loops0;
  const std::vector<int>& loops = problem.loops;
  std::vector<std::vector<double>> cost(loops0.size(), std::vector<double>(loops.size()));
  for (size_t a = 0; a < loops0.size(); ++a) {
    for (size_t b = 0; b < loops.size(); ++b) {
      cost[a][b] = (carry.m * problem.from.Raw(loops0[a]) + carry.t - problem.to.Raw(loops[b]))
                       .squaredNorm();
    }
  }
  Penalize(problem.pins, loops0, loops, problem.allowed, &cost);
  return Assign(cost);
}

// How far the carried loops, and the enclosing outline (holes), lie from their matches
// (CarriedDistance, summed): what tells turned maps apart (ChooseMatch).
double ScoreCarried(const MatchProblem& problem, const std::vector<int>& assignment,
                    const Affine& carry) {
  double score = problem.outline0 >= 0 ? CarriedDistance(problem.from, problem.to, problem.outline0,
                                                         problem.outline, carry)
                                       : 0.0;
  for (size_t a = 0; a < problem.loops0.size(); ++a) {
    score += CarriedDistance(problem.from, problem.to, problem.loops0[a],
                             problem.loops[assignment[a]], carry);
  }
  return score;
}

// Drawing 1's loops matched to the other drawing's from the map `start.carry`: by the carried
// area centroids, then (with `start.refit`) the map fitted to the matched centroids (affine
// images of each other in a copy) and the loops matched again, until the match settles. Scored
// by ScoreCarried.
HoleMatch MatchLoopsFrom(const MatchProblem& problem, const StartMap& start) {
  HoleMatch out;
  Affine carry = start.carry;
  for (int round = 0; round <= kMaxHoleRematches; ++round) {
    std::vector<int> again = AssignCarried(problem, carry);
    if (again == out.assignment) break;
    out.assignment = std::move(again);
    std::vector<std::pair<Point, Point>> matched;
    for (size_t a = 0; a < problem.loops0.size(); ++a) {
      matched.emplace_back(problem.from.Raw(problem.loops0[a]),
                           problem.to.Raw(problem.loops[out.assignment[a]]));
    }
    Affine fit;
    if (!start.refit || !FitAffine(matched, &fit)) break;
    carry = fit;
  }
  out.carry = carry;
  out.score = ScoreCarried(problem, out.assignment, carry);
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
HoleMatch MatchTurned(const MatchProblem& problem, const Affine& start, const Point& c,
                      HoleMatch first) {
  std::vector<HoleMatch> candidates;
  candidates.push_back(std::move(first));
  const int turns = problem.loops0.size() <= kMaxHolesForTurns ? kRotationHypotheses : 1;
  for (int j = 0; j < turns; ++j) {
    const double angle = 2.0 * std::numbers::pi * j / kRotationHypotheses;
    const Eigen::Matrix2d r{{std::cos(angle), -std::sin(angle)},
                            {std::sin(angle), std::cos(angle)}};
    // p -> start(c + r (p - c))
    const Affine turned{start.m * r, start.m * (c - r * c) + start.t};
    candidates.push_back(MatchLoopsFrom(problem, {.carry = turned, .refit = true}));
  }
  return ChooseMatch(std::move(candidates),
                     SamplingFloor(problem.to, problem.loops, problem.outline));
}

struct HoleMatchOptions {
  // Carry drawing 1's holes by the affine map of the outline onto its match; false (drawing 1
  // against itself): compare the centroids in the bounding-box normalisation.
  bool carry_by_outline = true;
};

// The holes compared by their centroids in the bounding-box normalisation (no map).
HoleMatch MatchByNormalisedCentroids(const MatchProblem& holes) {
  const std::vector<int>& holes0 = holes.loops0;
  std::vector<std::vector<double>> cost(holes0.size(), std::vector<double>(holes.loops.size()));
  for (size_t i = 0; i < holes0.size(); ++i) {
    for (size_t j = 0; j < holes.loops.size(); ++j) {
      cost[i][j] =
          ((*holes.from.centroid)[holes0[i]] - (*holes.to.centroid)[holes.loops[j]]).squaredNorm();
    }
  }
  Penalize(holes.pins, holes0, holes.loops, holes.allowed, &cost);
  HoleMatch out;
  out.assignment = Assign(cost);
  return out;
}

// The holes of drawing 1's component (outline0, loops0) matched to those of its match in another
// drawing (outline, loops). Drawing 1's holes are carried by the least-squares affine map of the
// outline onto its match (so a sheared, rotated copy matches hole to hole where the bounding
// boxes pair neighbours; MatchLoopsFrom). An outline alone may not fix the map (a round one: any
// rotation fits it), so when the holes' centroids spread in both directions (SpreadInTheFlat)
// the map is also refitted to them, starting from the outline's map turned about the outline's
// centroid (MatchTurned, ChooseMatch: of the candidates that score about as well as the best, the
// one turning least from the outline's map). Without a map (drawing 1 itself, or a degenerate
// fit), MatchByNormalisedCentroids.
HoleMatch MatchHoles(const MatchProblem& holes, const HoleMatchOptions& options) {
  const LoopSet& from = holes.from;
  const LoopSet& to = holes.to;
  const Curve& a = (*from.curves)[holes.outline0];
  const Curve& b = (*to.curves)[holes.outline];
  Affine carry;
  if (options.carry_by_outline && !holes.loops0.empty() &&
      OutlineAffine(a, b, AlignStart(a, b, from.centre, from.scale, to.centre, to.scale), &carry)) {
    HoleMatch unturned = MatchLoopsFrom(holes, {.carry = carry, .refit = false});
    std::vector<Point> centroids0;
    for (const int h : holes.loops0) centroids0.push_back(from.Raw(h));
    if (!SpreadInTheFlat(centroids0)) return unturned;
    return MatchTurned(holes, carry, from.Raw(holes.outline0), std::move(unturned));
  }
  return MatchByNormalisedCentroids(holes);
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

// Drawing d's loops as the matching sees them.
LoopSet LoopSetOf(const NormalisedLoops& loops, int d) {
  return LoopSet{&loops.curves[d], &loops.centroid[d], loops.centre[d], loops.scale[d]};
}

// The outer loops of `graph` (one per component), in order.
std::vector<int> OutlinesOf(const BoundaryGraph& graph) {
  std::vector<int> out;
  for (size_t l = 0; l < graph.loops.size(); ++l) {
    if (graph.loops[l].outer) out.push_back(static_cast<int>(l));
  }
  return out;
}

// The holes of `graph`'s component `component`, in order.
std::vector<int> HolesOf(const BoundaryGraph& graph, int component) {
  std::vector<int> out;
  for (size_t l = 0; l < graph.loops.size(); ++l) {
    const BoundaryLoop& loop = graph.loops[l];
    if (!loop.outer && loop.component == component) out.push_back(static_cast<int>(l));
  }
  return out;
}

// The cost of pairing drawing 1's outlines `outer0` with drawing d's `outer`: squared distance
// of the normalised centroids, plus 1e6 between components with different hole counts (which
// `same_holes` also rules out for the turned matches).
std::vector<std::vector<double>> ComponentCosts(const std::vector<BoundaryGraph>& graphs,
                                                const NormalisedLoops& loops, int d,
                                                const std::vector<int>& outer0,
                                                const std::vector<int>& outer,
                                                Allowed* same_holes) {
  const std::vector<std::vector<Point>>& centroid = loops.centroid;
  std::vector<std::vector<double>> cost(outer0.size(), std::vector<double>(outer.size()));
  for (size_t i = 0; i < outer0.size(); ++i) {
    const int h0 =
        static_cast<int>(HolesOf(graphs[0], graphs[0].loops[outer0[i]].component).size());
    for (size_t j = 0; j < outer.size(); ++j) {
      const int hd =
          static_cast<int>(HolesOf(graphs[d], graphs[d].loops[outer[j]].component).size());
      (*same_holes)[i][j] = h0 == hd;
      cost[i][j] =
          (centroid[0][outer0[i]] - centroid[d][outer[j]]).squaredNorm() + (h0 != hd ? 1e6 : 0.0);
    }
  }
  return cost;
}

// Components spread across the drawing: drawing 1's placement in drawing d's bounding box (the
// match `assignment`) against that placement turned about drawing 1's centre and refitted
// (MatchTurned): a rearranged drawing (a turned copy) pairs each part with its image, not with
// whichever part now sits where it sat.
std::vector<int> MatchComponentsTurned(const NormalisedLoops& loops, int d,
                                       const std::vector<int>& outer0,
                                       const std::vector<int>& outer, const Pins& pins,
                                       const Allowed& same_holes, std::vector<int> assignment) {
  const LoopSet from0 = LoopSetOf(loops, 0);
  const LoopSet to = LoopSetOf(loops, d);
  const double s = loops.scale[d] / loops.scale[0];
  const Affine place{s * Eigen::Matrix2d::Identity(), loops.centre[d] - s * loops.centre[0]};
  HoleMatch placed;  // the placement's own match, scored under `place`
  placed.assignment = std::move(assignment);
  placed.carry = place;
  placed.score = 0.0;
  for (size_t i = 0; i < outer0.size(); ++i) {
    placed.score += CarriedDistance(from0, to, outer0[i], outer[placed.assignment[i]], place);
  }
  const MatchProblem problem{from0, to, -1, -1, outer0, outer, pins, same_holes};
  return MatchTurned(problem, place, loops.centre[0], std::move(placed)).assignment;
}

// Drawing d's outlines matched to drawing 1's `outer0`: match[i] is the outline paired with
// outer0[i] (by normalised centroids, then MatchComponentsTurned where drawing 1's components
// spread across it).
std::vector<int> MatchComponents(const std::vector<BoundaryGraph>& graphs,
                                 const NormalisedLoops& loops, int d,
                                 const std::vector<int>& outer0, const Pins& pins) {
  const LoopSet from0 = LoopSetOf(loops, 0);
  std::vector<Point> centroids0;  // drawing 1's components, as drawn
  for (const int l : outer0) centroids0.push_back(from0.Raw(l));
  const std::vector<int> outer = OutlinesOf(graphs[d]);
  Allowed same_holes(outer0.size(), std::vector<bool>(outer.size()));
  std::vector<std::vector<double>> cost =
      ComponentCosts(graphs, loops, d, outer0, outer, &same_holes);
  Penalize(pins, outer0, outer, {}, &cost);
  std::vector<int> assignment = Assign(cost);
  if (d > 0 && SpreadInTheFlat(centroids0)) {
    assignment =
        MatchComponentsTurned(loops, d, outer0, outer, pins, same_holes, std::move(assignment));
  }
  std::vector<int> match;
  for (size_t i = 0; i < outer0.size(); ++i) match.push_back(outer[assignment[i]]);
  return match;
}

// In every drawing d, the holes of the component whose outline is outlines[d]; INVALID_ARGUMENT
// naming the drawing where their count differs from drawing 1's (`component`: drawing 1's
// index of the component, for the message).
absl::StatusOr<std::vector<std::vector<int>>> HolesOfMatch(const std::vector<BoundaryGraph>& graphs,
                                                           const std::vector<int>& outlines,
                                                           size_t component) {
  const int num_shapes = static_cast<int>(graphs.size());
  std::vector<std::vector<int>> holes(num_shapes);
  for (int d = 0; d < num_shapes; ++d) {
    holes[d] = HolesOf(graphs[d], graphs[d].loops[outlines[d]].component);
    if (holes[d].size() != holes[0].size()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "drawing ", d + 1, ": the component matched to drawing 1's component ", component + 1,
          " has ", holes[d].size(), " holes instead of ", holes[0].size()));
    }
  }
  return holes;
}

// Appends the loop groups of drawing 1's component `component` (outlines[d]: its match in
// drawing d): the outline, then its holes matched by MatchHoles. The map that carried the holes
// also aligns each hole's start, and the outline's: a round outline has no other.
absl::Status AddComponentGroups(const std::vector<BoundaryGraph>& graphs,
                                const NormalisedLoops& loops, const std::vector<int>& outlines,
                                size_t component, const std::vector<Pins>& loop_pins,
                                LoopGroups* groups) {
  const int num_shapes = static_cast<int>(graphs.size());
  groups->loops.push_back(outlines);
  groups->outer.push_back(true);
  groups->component.push_back(static_cast<int>(component));
  const size_t outer_group = groups->carry.size();
  groups->carry.emplace_back(num_shapes);
  absl::StatusOr<std::vector<std::vector<int>>> holes = HolesOfMatch(graphs, outlines, component);
  if (!holes.ok()) return holes.status();
  std::vector<std::vector<int>> hole_match(num_shapes);
  std::vector<std::optional<Affine>> carry(num_shapes);
  const LoopSet from0 = LoopSetOf(loops, 0);
  const Allowed any;
  for (int d = 0; d < num_shapes; ++d) {
    const LoopSet to = LoopSetOf(loops, d);
    const MatchProblem problem{from0,       to,          outlines[0],  outlines[d],
                               (*holes)[0], (*holes)[d], loop_pins[d], any};
    HoleMatch match = MatchHoles(problem, {.carry_by_outline = d > 0});
    carry[d] = match.carry;
    for (size_t a = 0; a < (*holes)[0].size(); ++a) {
      hole_match[d].push_back((*holes)[d][match.assignment[a]]);
    }
  }
  groups->carry[outer_group] = carry;
  for (size_t a = 0; a < (*holes)[0].size(); ++a) {
    std::vector<int> hg(num_shapes);
    for (int d = 0; d < num_shapes; ++d) hg[d] = hole_match[d][a];
    groups->loops.push_back(hg);
    groups->outer.push_back(false);
    groups->component.push_back(static_cast<int>(component));
    groups->carry.push_back(carry);
  }
  return absl::OkStatus();
}

}  // namespace

NormalisedLoops NormaliseLoops(const std::vector<BoundaryGraph>& graphs) {
  const int num_shapes = static_cast<int>(graphs.size());
  NormalisedLoops out;
  out.centre.resize(num_shapes);
  out.scale.resize(num_shapes);
  out.centroid.resize(num_shapes);
  out.curves.resize(num_shapes);
  for (int d = 0; d < num_shapes; ++d) {
    Point lo = graphs[d].loops[0].points[0], hi = lo;
    for (const BoundaryLoop& l : graphs[d].loops) {
      for (const Point& p : l.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
    out.centre[d] = 0.5 * (lo + hi);
    out.scale[d] = std::max((hi - lo).norm(), 1e-300);
    for (const BoundaryLoop& l : graphs[d].loops) {
      out.centroid[d].push_back((Centroid(l.points) - out.centre[d]) / out.scale[d]);
      out.curves[d].push_back(MakeCurve(l.points));
    }
  }
  return out;
}

// Turning angle and position of `a` (or its image under `carry`) against each of kAlignSamples
// cyclic shifts of `b`'s samples; the cheapest shift's arc length.
double AlignStart(const Curve& a, const Curve& b, const Point& ca, double sa, const Point& cb,
                  double sb, const Affine* carry) {
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

absl::StatusOr<LoopGroups> MatchLoopGroups(const std::vector<BoundaryGraph>& graphs,
                                           const NormalisedLoops& loops,
                                           const std::vector<std::vector<Point>>& marks) {
  const int num_shapes = static_cast<int>(graphs.size());
  // Correspondence marks decide which loops and components pair where they sit on them.
  std::vector<Pins> loop_pins, component_pins;
  if (absl::Status s = PinByMarks(graphs, loops.curves, marks, &loop_pins, &component_pins);
      !s.ok()) {
    return s;
  }
  const std::vector<int> outer0 = OutlinesOf(graphs[0]);
  std::vector<std::vector<int>> component_match(num_shapes);  // [d][c0] -> outer loop in d
  for (int d = 0; d < num_shapes; ++d) {
    component_match[d] = MatchComponents(graphs, loops, d, outer0, component_pins[d]);
  }
  LoopGroups groups;
  for (size_t i = 0; i < outer0.size(); ++i) {
    std::vector<int> outlines(num_shapes);
    for (int d = 0; d < num_shapes; ++d) outlines[d] = component_match[d][i];
    if (absl::Status s = AddComponentGroups(graphs, loops, outlines, i, loop_pins, &groups);
        !s.ok()) {
      return s;
    }
  }
  groups.seamed.assign(groups.size(), false);
  for (int g = 0; g < groups.size(); ++g) {
    for (int d = 0; d < num_shapes; ++d) {
      for (const auto& [loop, edge] : graphs[d].loops[groups.loops[g][d]].twin) {
        groups.seamed[g] = groups.seamed[g] || loop >= 0;
      }
    }
  }
  return groups;
}

}  // namespace inbetween::solver::boundary_internal
