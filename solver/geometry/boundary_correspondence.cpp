// S-Sec.1 "Boundary Tool" and "Initial Meshing" (compatible reparameterization): loop matching,
// marks or automatic alignment, common breakpoints (marks, corners and cut/opening ends of every
// drawing, mirrored across each cohesive zone), equal vertex counts per segment between them.
// The loop matching (boundary_loop_matching.cpp) and the parameterization of each loop group
// (boundary_parameterization.cpp) come first; this file holds the rest, from the breakpoints to
// the sampled loops, and the entry point that runs the three in order.
#include "solver/geometry/boundary_correspondence.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "absl/strings/str_cat.h"
#include "solver/core/error_reason.h"
#include "solver/geometry/boundary_correspondence_internal.h"
#include "solver/geometry/primitives.h"
#include "solver/geometry/resample_outline.h"

namespace inbetween::solver {
namespace {

using boundary_internal::Curve;
using boundary_internal::GroupedLoops;
using boundary_internal::Param;
using boundary_internal::Parameterization;
using boundary_internal::Wrap01;

// The automatic vertex budget per drawing (BoundaryCorrespondenceOptions::vertices = 0): at
// least this, and twice the breakpoints.
constexpr int kDefaultVertices = 64;
// Breakpoints closer than this in the common parameter are one (AddBreak).
constexpr double kSameT = 1e-9;

// A mark's interval shorter than this fraction of the drawing's diagonal in some drawing (a mark
// beside another breakpoint that it did not snap to) is refused naming the mark: it would reach
// the mesher as a cusp.
constexpr double kMarkSliverRelative = 1e-6;
// Corners closer than this fraction of a drawing's diagonal share one breakpoint (NearBreak);
// with the outline tolerance in force, corners closer than the tolerance do too.
constexpr double kCornerMergeRelative = 1e-4;

// One side of a cut/opening run of a drawing: arc lengths [a0, a1] on loop `group`, collocated
// with [b0, b1] of `twin_group` walked the other way.
struct Run {
  int group, twin_group;
  double a0, a1, b0, b1;
  // Mirror of arc length x (a0 < x < a1, unwrapped past the loop start if needed).
  double Mirror(double x) const { return b1 - (x - a0); }
};

// Drawing g's cut/opening runs: maximal stretches of a loop's edges whose twins continue along
// one other stretch, each side a run of its own, on loop groups (group_of_loop).
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

// Whether, in every drawing d, the outline between common parameters lo < hi lies within tol[d]
// of the chord between its ends.
bool WithinTolerance(double lo, double hi, const std::vector<const Curve*>& curves,
                     const std::vector<const Param*>& params, const std::vector<double>& tol) {
  for (size_t d = 0; d < curves.size(); ++d) {
    double far;
    if (ChordDeviation(*curves[d], params[d]->Forward(lo), params[d]->Forward(hi), &far) > tol[d]) {
      return false;
    }
  }
  return true;
}

// Whether every piece between consecutive common parameters `ts` (and from the last to t1) lies
// within the tolerance in every drawing (WithinTolerance).
bool PiecesWithinTolerance(const std::vector<double>& ts, double t1,
                           const std::vector<const Curve*>& curves,
                           const std::vector<const Param*>& params,
                           const std::vector<double>& tol) {
  for (size_t k = 0; k < ts.size(); ++k) {
    if (!WithinTolerance(ts[k], k + 1 < ts.size() ? ts[k + 1] : t1, curves, params, tol)) {
      return false;
    }
  }
  return true;
}

// `count` common parameters spread evenly from t0 towards t1 (t1 itself not among them).
std::vector<double> EvenParams(double t0, double t1, int count) {
  std::vector<double> ts;
  for (int k = 0; k < count; ++k) ts.push_back(t0 + (t1 - t0) * k / count);
  return ts;
}

// The common parameters in (t0, t1) of every drawing's outline vertices, sorted, with those
// closer than `min_gap` to the previous one (or to t0, t1) left out.
std::vector<double> OutlineVertexParams(double t0, double t1,
                                        const std::vector<const Curve*>& curves,
                                        const std::vector<const Param*>& params, double min_gap) {
  std::vector<double> all;
  for (size_t d = 0; d < curves.size(); ++d) {
    const Curve& c = *curves[d];
    const Param& p = *params[d];
    const double length = c.length(), a0 = p.Forward(t0), a1 = p.Forward(t1);
    const int n = static_cast<int>(c.p.size());
    const double base = std::floor(a0 / length) * length;
    int k =
        static_cast<int>(std::upper_bound(c.cum.begin(), c.cum.end(), a0 - base) - c.cum.begin());
    for (int steps = 0; steps < n; ++steps, ++k) {
      const double arc = base + (k / n) * length + c.cum[k % n];
      if (arc >= a1) break;
      if (arc <= a0) continue;
      const double t = Wrap01(p.Inverse(arc));
      all.push_back(t < t0 ? t + 1.0 : t);
    }
  }
  std::sort(all.begin(), all.end());
  std::vector<double> out;
  double last = t0;
  for (double t : all) {
    if (t - last >= min_gap && t1 - t >= min_gap) out.push_back(t), last = t;
  }
  return out;
}

// Common parameters for the interval [ts[0], t1) whose even vertices `ts` leave some drawing's
// outline farther than tol[d] from a chord. The even ones are kept where they suffice (an outline
// already within the tolerance samples as before). Otherwise the vertices are placed greedily:
// from each vertex, the farthest of every drawing's outline vertices (as common parameters) up to
// which all drawings stay within the tolerance of the chord, and never farther than the even
// spacing. A rounded tip drawn with many small turns gets vertices along it by each drawing's own
// curvature, where the corner test (a turn above corner_angle_degrees in one step) saw none.
// Halving each strayed chord at its farthest vertex instead adds about a quarter more vertices
// where it adds any, and their meshes more still (`scripts/bench correspondence --icons`,
// docs/benchmarks.md). The last two pieces are then evened out, so that no sliver edge ends the
// interval.
std::vector<double> RefineToTolerance(const std::vector<double>& ts, double t1,
                                      const std::vector<const Curve*>& curves,
                                      const std::vector<const Param*>& params,
                                      const std::vector<double>& tol) {
  if (PiecesWithinTolerance(ts, t1, curves, params, tol)) return ts;
  // Pieces narrower than kMinPiece in t are not made (coincident vertices would follow).
  constexpr double kMinPiece = 1e-7;
  const double t0 = ts[0];
  const double max_step = (t1 - t0) / static_cast<double>(ts.size());
  const std::vector<double> cand = OutlineVertexParams(t0, t1, curves, params, kMinPiece);
  std::vector<double> out = {t0};
  size_t next = 0;  // first candidate past the current vertex
  for (;;) {
    const double cur = out.back();
    const double reach = cur + max_step;
    if (t1 <= reach && WithinTolerance(cur, t1, curves, params, tol)) break;
    while (next < cand.size() && cand[next] <= cur) ++next;
    double best = -1.0;
    size_t k = next;
    for (; k < cand.size() && cand[k] <= reach; ++k) {
      if (!WithinTolerance(cur, cand[k], curves, params, tol)) break;
      best = cand[k];
    }
    const bool all_fit = k == cand.size() || cand[k] > reach;
    if (all_fit && reach < t1 - kMinPiece && WithinTolerance(cur, reach, curves, params, tol)) {
      best = reach;
    }
    // Between two neighbouring candidates no drawing has an outline vertex, so the first one
    // always fits; it is taken even if it does not (a piece narrower than kMinPiece).
    if (best < 0.0) best = next < cand.size() ? cand[next] : 0.5 * (cur + t1);
    if (best >= t1 - kMinPiece) break;
    out.push_back(best);
  }
  // Even out the last two pieces: the last vertex moves to the candidate (or the midpoint) that
  // keeps both pieces within the tolerance and the shorter one longest.
  if (out.size() >= 2) {
    const double lo = out[out.size() - 2];
    double& last = out.back();
    auto shorter = [&](double t) { return std::min(t - lo, t1 - t); };
    std::vector<double> options = {0.5 * (lo + t1)};
    for (double t : cand) {
      if (t > lo && t < t1) options.push_back(t);
    }
    for (double t : options) {
      if (shorter(t) > shorter(last) && t - lo <= max_step && t1 - t <= max_step &&
          WithinTolerance(lo, t, curves, params, tol) &&
          WithinTolerance(t, t1, curves, params, tol)) {
        last = t;
      }
    }
  }
  return out;
}

// Classes of intervals that must share a vertex count (twins across seam runs).
struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int Find(int x) { return parent[x] == x ? x : parent[x] = Find(parent[x]); }
  void Unite(int a, int b) { parent[Find(a)] = Find(b); }
};

// Where the two sides of a run must agree: whether common parameter t lies strictly inside run
// r under p, with its arc (unwrapped past r.a0) in `arc`.
bool InsideRun(const Run& r, const Param& p, double t, double* arc) {
  double a = p.Forward(t);
  while (a < r.a0) a += p.length;
  while (a >= r.a0 + p.length) a -= p.length;
  *arc = a;
  const double eps = 1e-9 * p.length;
  return a > r.a0 + eps && a < r.a1 - eps;
}

// The steps after the parameterization, as methods run in order: FindBreakpoints (primary
// breakpoints, mirrored across the seam runs, then the marks' sliver check), then Sample
// (intervals between breakpoints and their twins, vertex counts, each interval's vertices as
// common parameters, every drawing sampled at them). Each step reads what the earlier ones
// left in the members.
class CompatibleSampling {
 public:
  CompatibleSampling(const std::vector<BoundaryGraph>& graphs, const GroupedLoops& loops,
                     const Parameterization& param, const BoundaryCorrespondenceOptions& options)
      : graphs_(graphs),
        loops_(loops),
        param_(param),
        options_(options),
        num_shapes_(loops.num_shapes()),
        num_groups_(loops.num_groups()) {}

  // The breakpoints of every loop group; INVALID_ARGUMENT for cuts whose two sides cannot share
  // vertices and for marks beside another breakpoint.
  absl::Status FindBreakpoints();
  // Intervals, vertex counts and the sampled loops into `out` (after FindBreakpoints).
  void Sample(BoundaryCorrespondence* out);

 private:
  const Curve& curve(int d, int g) const { return loops_.curve(d, g); }
  const Param& param(int d, int g) const { return param_.param[d][g]; }
  double scale(int d) const { return loops_.normalised.scale[d]; }

  void FindSeamRuns();
  bool AddBreak(int g, double t);
  bool NearBreak(int g, double t) const;
  void AddCornerBreaks(int g, int d);
  void AddPrimaryBreaks();
  size_t TotalBreaks() const;
  bool MirrorRound();
  absl::Status MismatchedCutsError() const;
  absl::Status MirrorBreaks();
  absl::Status CheckMarkSliver(size_t m) const;

  double IntervalEnd(int g, int i) const;
  int IntervalOf(int g, double t) const;
  int NextInLoop(int gi) const;
  UnionFind LinkTwinIntervals();
  void CountVertices(UnionFind* classes);
  struct GroupOutlines {
    std::vector<const Curve*> curves;
    std::vector<const Param*> params;
    std::vector<double> tol;
  };
  GroupOutlines OutlinesOf(int g) const;
  bool Refines() const;
  std::vector<bool> HasTwin() const;
  bool EvenWithinTolerance(int g, int i, int count) const;
  void RefineTwinClasses(UnionFind* classes);
  void PlaceVertices();
  void SampleLoops(int d, Points* flat, double* achieved) const;
  void CollocateTwins(int d, Points* flat, std::vector<int>* edge_twin) const;
  void FindMarkVertices(std::vector<int>* mark_vertices) const;

  const std::vector<BoundaryGraph>& graphs_;
  const GroupedLoops& loops_;
  const Parameterization& param_;
  const BoundaryCorrespondenceOptions& options_;
  const int num_shapes_, num_groups_;
  std::vector<std::vector<Run>> runs_;           // per drawing: its seam runs
  std::vector<std::vector<double>> breaks_;      // per group: breakpoints, sorted, in [0, 1)
  std::vector<int> interval_start_;              // group g's intervals: [start[g], start[g + 1])
  std::vector<std::vector<int>> twin_interval_;  // [d][interval]: its twin in drawing d, or -1
  std::vector<int> count_;                       // per interval: its vertex count
  std::vector<std::vector<double>> interval_t_;  // per interval: its vertices' parameters
  std::vector<int> first_vertex_;                // per interval: its first global vertex
};

// Seam runs per drawing, on loop groups rather than the drawing's own loop numbers.
void CompatibleSampling::FindSeamRuns() {
  std::vector<std::vector<int>> group_of_loop(num_shapes_);
  for (int d = 0; d < num_shapes_; ++d) {
    group_of_loop[d].assign(graphs_[d].loops.size(), -1);
    for (int g = 0; g < num_groups_; ++g) group_of_loop[d][loops_.groups.loops[g][d]] = g;
  }
  runs_.resize(num_shapes_);
  for (int d = 0; d < num_shapes_; ++d) {
    runs_[d] = SeamRuns(graphs_[d], group_of_loop[d], loops_.normalised.curves[d]);
  }
}

// Adds breakpoint t (wrapped into [0, 1)) to group g unless one lies within kSameT; whether it
// was added.
bool CompatibleSampling::AddBreak(int g, double t) {
  t = Wrap01(t);
  std::vector<double>& b = breaks_[g];
  auto it = std::lower_bound(b.begin(), b.end(), t);
  const bool near_next = it != b.end() && *it - t < kSameT;
  const bool near_prev = it != b.begin() && t - *(it - 1) < kSameT;
  const bool near_wrap = !b.empty() && (t + 1 - b.back() < kSameT || b.front() + 1 - t < kSameT);
  if (near_next || near_prev || near_wrap) return false;
  b.insert(it, t);
  return true;
}

// Whether a corner at t lies within kCornerMergeRelative (or the outline tolerance, when the
// sampling refines to it) of a neighbouring breakpoint of group g in some drawing. Two drawings'
// corners that the correspondence puts a hair apart would make a sliver interval that every
// drawing repeats (the mesher refuses it as a cusp), and so would two corners of one drawing a
// notch apart (a tip flattened into several sharp turns): such a corner is left to the
// breakpoint; its drawing's vertex then sits that close to the corner, within the outline
// tolerance (which the refinement checks, and meets with a vertex of its own where it must).
// The sliver's triangles were what the middle frame's worst distortion measured on a face's
// eye corner (`scripts/bench correspondence`, principles_appeal).
bool CompatibleSampling::NearBreak(int g, double t) const {
  const double merge = std::max(kCornerMergeRelative, Refines() ? options_.tolerance : 0.0);
  bool near = false;
  const std::vector<double>& b = breaks_[g];
  auto it = std::lower_bound(b.begin(), b.end(), t);
  for (double other :
       {it != b.end() ? *it : b.front() + 1.0, it != b.begin() ? *(it - 1) : b.back() - 1.0}) {
    for (int e = 0; e < num_shapes_ && !near; ++e) {
      const Param& p = param(e, g);
      const double gap = std::abs(p.Forward(Wrap01(t)) - p.Forward(Wrap01(other)));
      near = std::min(gap, p.length - gap) < merge * scale(e);
    }
  }
  return near;
}

// Drawing d's corners on group g, as breakpoints where no other is near (NearBreak).
void CompatibleSampling::AddCornerBreaks(int g, int d) {
  const Curve& c = curve(d, g);
  for (int k : FindCorners(c.p, options_.corner_angle_degrees)) {
    const double t = Wrap01(param(d, g).Inverse(c.cum[k]));
    if (!NearBreak(g, t)) AddBreak(g, t);
  }
}

// The breakpoints before mirroring: each loop's start, the pinned parameters (marks or matched
// corners), every drawing's corners, then the ends of every seam run.
void CompatibleSampling::AddPrimaryBreaks() {
  breaks_.assign(num_groups_, {});
  for (int g = 0; g < num_groups_; ++g) {
    breaks_[g].push_back(0.0);
    for (int d = 0; d < num_shapes_; ++d) {
      if (d == 0) {
        for (double t : param_.pinned_t[g]) AddBreak(g, t);
      }
      AddCornerBreaks(g, d);
    }
  }
  for (int d = 0; d < num_shapes_; ++d) {
    for (const Run& r : runs_[d]) {
      AddBreak(r.group, param(d, r.group).Inverse(r.a0));
      AddBreak(r.group, param(d, r.group).Inverse(r.a1));
    }
  }
}

// Breakpoints of all groups together: what bounds the mirroring (MirrorBreaks).
size_t CompatibleSampling::TotalBreaks() const {
  size_t total = 0;
  for (const std::vector<double>& b : breaks_) total += b.size();
  return total;
}

// Every breakpoint inside a run mirrored onto its other side; whether any was added.
bool CompatibleSampling::MirrorRound() {
  bool added = false;
  for (int d = 0; d < num_shapes_; ++d) {
    for (const Run& r : runs_[d]) {
      const std::vector<double> current = breaks_[r.group];
      for (double t : current) {
        double a;
        if (!InsideRun(r, param(d, r.group), t, &a)) continue;
        added |= AddBreak(r.twin_group, param(d, r.twin_group).Inverse(r.Mirror(a)));
      }
    }
  }
  return added;
}

// What to do when the mirrors do not settle, naming the drawings with cuts or openings.
absl::Status CompatibleSampling::MismatchedCutsError() const {
  std::string with_cuts;
  int listed = 0;
  for (int d = 0; d < num_shapes_; ++d) {
    if (runs_[d].empty()) continue;
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

// Mirrors breakpoints across the runs until both sides of every run agree. Cuts of several
// drawings along the same stretch of boundary agree only where their ends sit at the same
// common parameter (marks at both ends, or identical geometry between marks); otherwise each
// mirror adds points the other mirrors again, without end. Bounded: beyond kMaxMirrorGrowth
// times the breakpoints before mirroring (and at least kMinMirrorBreaks in all) the drawings are
// refused with what to do, before the correspondence takes minutes and the mesh explodes.
absl::Status CompatibleSampling::MirrorBreaks() {
  constexpr int kMaxMirrorGrowth = 8, kMinMirrorBreaks = 4096;
  const size_t primary_breaks = TotalBreaks();
  const size_t max_breaks = std::max<size_t>(kMinMirrorBreaks, kMaxMirrorGrowth * primary_breaks);
  for (int round = 0; round < 16; ++round) {
    if (!MirrorRound()) break;
    if (TotalBreaks() > max_breaks) return MismatchedCutsError();
  }
  return absl::OkStatus();
}

// Mark m beside another breakpoint (kMarkSliverRelative) is named here rather than left to fail
// in the mesher as a cusp of some drawing.
absl::Status CompatibleSampling::CheckMarkSliver(size_t m) const {
  const auto [g, at0] = param_.mark_at[m];
  const std::vector<double>& b = breaks_[g];
  if (b.size() < 2) return absl::OkStatus();
  const double t = Wrap01((at0 - param_.marks[g][0].first) / curve(0, g).length());
  size_t i = 0;
  double best = 2.0;
  for (size_t j = 0; j < b.size(); ++j) {
    const double gap = std::abs(b[j] - t);
    if (std::min(gap, 1.0 - gap) < best) best = std::min(gap, 1.0 - gap), i = j;
  }
  const double t_prev = i > 0 ? b[i - 1] : b.back() - 1.0;
  const double t_next = i + 1 < b.size() ? b[i + 1] : b[0] + 1.0;
  for (int d = 0; d < num_shapes_; ++d) {
    const Param& p = param(d, g);
    const double here = p.Forward(b[i]);
    const double before =
        here - (t_prev < 0 ? p.Forward(t_prev + 1.0) - p.length : p.Forward(t_prev));
    const double after =
        (t_next > 1.0 ? p.Forward(t_next - 1.0) + p.length : p.Forward(t_next)) - here;
    const double shortest = std::min(before, after);
    if (shortest < kMarkSliverRelative * scale(d)) {
      const Point at = curve(d, g).At(here);
      return absl::InvalidArgumentError(absl::StrCat(
          "drawing ", d + 1, ": correspondence mark ", m + 1, " at (", at.x(), ", ", at.y(),
          ") sits ", shortest,
          " from another breakpoint of its boundary (a corner of some "
          "drawing or another mark), too close to keep apart; move the mark onto that corner "
          "or away from it"));
    }
  }
  return absl::OkStatus();
}

absl::Status CompatibleSampling::FindBreakpoints() {
  FindSeamRuns();
  AddPrimaryBreaks();
  if (absl::Status s = MirrorBreaks(); !s.ok()) return s;
  for (size_t m = 0; m < param_.mark_at.size(); ++m) {
    if (absl::Status s = CheckMarkSliver(m); !s.ok()) return s;
  }
  return absl::OkStatus();
}

// The common parameter where interval i of group g ends (past 1 for the last).
double CompatibleSampling::IntervalEnd(int g, int i) const {
  return i + 1 < static_cast<int>(breaks_[g].size()) ? breaks_[g][i + 1] : breaks_[g][0] + 1.0;
}

// The interval of group g (its index in the group) that holds parameter t.
int CompatibleSampling::IntervalOf(int g, double t) const {
  t = Wrap01(t);
  const std::vector<double>& b = breaks_[g];
  int i = static_cast<int>(std::upper_bound(b.begin(), b.end(), t) - b.begin()) - 1;
  return i < 0 ? static_cast<int>(b.size()) - 1 : i;
}

// The global interval after gi in its loop.
int CompatibleSampling::NextInLoop(int gi) const {
  int g = static_cast<int>(std::upper_bound(interval_start_.begin(), interval_start_.end(), gi) -
                           interval_start_.begin()) -
          1;
  return gi + 1 < interval_start_[g + 1] ? gi + 1 : interval_start_[g];
}

// Global interval numbers, and each run's intervals paired with their mirror images
// (twin_interval_); the classes of intervals that must share a vertex count.
UnionFind CompatibleSampling::LinkTwinIntervals() {
  interval_start_.assign(num_groups_ + 1, 0);
  for (int g = 0; g < num_groups_; ++g) {
    interval_start_[g + 1] = interval_start_[g] + static_cast<int>(breaks_[g].size());
  }
  const int num_intervals = interval_start_.back();
  twin_interval_.assign(num_shapes_, std::vector<int>(num_intervals, -1));
  UnionFind classes(num_intervals);
  for (int d = 0; d < num_shapes_; ++d) {
    for (const Run& r : runs_[d]) {
      for (int i = 0; i < static_cast<int>(breaks_[r.group].size()); ++i) {
        const double mid = 0.5 * (breaks_[r.group][i] + IntervalEnd(r.group, i));
        double a;
        if (!InsideRun(r, param(d, r.group), mid, &a)) continue;
        const int j = IntervalOf(r.twin_group, param(d, r.twin_group).Inverse(r.Mirror(a)));
        const int gi = interval_start_[r.group] + i, gj = interval_start_[r.twin_group] + j;
        twin_interval_[d][gi] = gj;
        twin_interval_[d][gj] = gi;
        classes.Unite(gi, gj);
      }
    }
  }
  return classes;
}

// Each interval's vertex count: its longest length in any drawing over that drawing's spacing
// (the perimeter over the budget: `vertices`, or automatic), at least a few per loop; the
// largest within each class of twins.
void CompatibleSampling::CountVertices(UnionFind* classes) {
  const int num_intervals = interval_start_.back();
  int total_corners = 0;
  for (int g = 0; g < num_groups_; ++g) total_corners += static_cast<int>(breaks_[g].size());
  const int budget =
      options_.vertices > 0 ? options_.vertices : std::max(kDefaultVertices, 2 * total_corners);
  std::vector<double> spacing(num_shapes_);
  for (int d = 0; d < num_shapes_; ++d) {
    double perimeter = 0;
    for (int g = 0; g < num_groups_; ++g) perimeter += curve(d, g).length();
    spacing[d] = perimeter / budget;
  }
  count_.assign(num_intervals, 1);
  for (int g = 0; g < num_groups_; ++g) {
    const int m = static_cast<int>(breaks_[g].size());
    const int minimum = m == 1 ? 4 : m <= 3 ? 2 : 1;
    for (int i = 0; i < m; ++i) {
      int c = minimum;
      for (int d = 0; d < num_shapes_; ++d) {
        const double len =
            param(d, g).Forward(IntervalEnd(g, i)) - param(d, g).Forward(breaks_[g][i]);
        c = std::max(c, static_cast<int>(std::lround(len / spacing[d])));
      }
      count_[interval_start_[g] + i] = c;
    }
  }
  std::vector<int> class_count(num_intervals, 0);
  for (int i = 0; i < num_intervals; ++i) {
    class_count[classes->Find(i)] = std::max(class_count[classes->Find(i)], count_[i]);
  }
  for (int i = 0; i < num_intervals; ++i) count_[i] = class_count[classes->Find(i)];
}

// Whether `count` vertices spread evenly over interval i of group g leave every drawing's outline
// within the tolerance of their chords.
bool CompatibleSampling::EvenWithinTolerance(int g, int i, int count) const {
  const GroupOutlines o = OutlinesOf(g);
  const double t1 = IntervalEnd(g, i);
  return PiecesWithinTolerance(EvenParams(breaks_[g][i], t1, count), t1, o.curves, o.params, o.tol);
}

// Whether the sampling refines to the outline tolerance: a tolerance, and no fixed vertex count.
bool CompatibleSampling::Refines() const {
  return options_.tolerance > 0.0 && options_.vertices <= 0;
}

// Per interval: whether it is some drawing's side of a cut or an opening (it has a twin).
std::vector<bool> CompatibleSampling::HasTwin() const {
  const int num_intervals = interval_start_.back();
  std::vector<bool> has_twin(num_intervals, false);
  for (int d = 0; d < num_shapes_; ++d) {
    for (int i = 0; i < num_intervals; ++i) has_twin[i] = has_twin[i] || twin_interval_[d][i] >= 0;
  }
  return has_twin;
}

// Group g's loop in every drawing, its parameterization and its outline tolerance (absolute).
CompatibleSampling::GroupOutlines CompatibleSampling::OutlinesOf(int g) const {
  GroupOutlines o;
  for (int d = 0; d < num_shapes_; ++d) {
    o.curves.push_back(&curve(d, g)), o.params.push_back(&param(d, g));
    o.tol.push_back(options_.tolerance * scale(d));
  }
  return o;
}

// Intervals on a cut or an opening (and their twins across it, one class) with a tolerance and
// no fixed vertex count: the class's common count raised (by a quarter at a time, up to
// kMaxTwinRefinement times) until its even spacing leaves every member's outline within the
// tolerance in every drawing. Even spacing, since each side repeats its twin's vertices
// mirrored (CollocateTwins); a lip that opens from a straight slit into a curve needs more than
// the slit's count.
void CompatibleSampling::RefineTwinClasses(UnionFind* classes) {
  if (!Refines()) return;
  constexpr int kMaxTwinRefinement = 64;
  const int num_intervals = interval_start_.back();
  const std::vector<bool> has_twin = HasTwin();
  std::vector<std::vector<std::pair<int, int>>> members(num_intervals);  // by class root
  for (int g = 0; g < num_groups_; ++g) {
    for (int i = 0; i < static_cast<int>(breaks_[g].size()); ++i) {
      const int gi = interval_start_[g] + i;
      if (has_twin[gi]) members[classes->Find(gi)].push_back({g, i});
    }
  }
  for (const std::vector<std::pair<int, int>>& list : members) {
    if (list.empty()) continue;
    const int first = count_[interval_start_[list[0].first] + list[0].second];
    int n = first;
    auto fits = [&](int count) {
      for (const auto& [g, i] : list) {
        if (!EvenWithinTolerance(g, i, count)) return false;
      }
      return true;
    };
    while (!fits(n) && n < kMaxTwinRefinement * first) n += std::max(1, n / 4);
    for (const auto& [g, i] : list) count_[interval_start_[g] + i] = n;
  }
}

// Each interval's vertices as common parameters: `count` evenly spaced, then (with a
// tolerance, and no fixed vertex count) refined until every drawing's polyline lies within the
// tolerance of its outline (RefineToTolerance). Intervals of a cut or opening keep the even
// spacing, which their twins repeat (RefineTwinClasses chose its count).
void CompatibleSampling::PlaceVertices() {
  const int num_intervals = interval_start_.back();
  interval_t_.assign(num_intervals, {});
  const std::vector<bool> has_twin = HasTwin();
  const bool refine = Refines();
  for (int g = 0; g < num_groups_; ++g) {
    for (int i = 0; i < static_cast<int>(breaks_[g].size()); ++i) {
      const int gi = interval_start_[g] + i;
      const double t0 = breaks_[g][i], t1 = IntervalEnd(g, i);
      std::vector<double>& ts = interval_t_[gi];
      ts = EvenParams(t0, t1, count_[gi]);
      if (!refine || has_twin[gi]) continue;
      const GroupOutlines o = OutlinesOf(g);
      ts = RefineToTolerance(ts, t1, o.curves, o.params, o.tol);
      count_[gi] = static_cast<int>(ts.size());
    }
  }
}

// Drawing d's vertices (`flat`, global numbering), uniform in the common parameter through the
// drawing's parameterization: arc length between breakpoints where that is linear (marks), the
// alignment's map otherwise. `achieved` grows to the farthest the outline strays from a chord.
void CompatibleSampling::SampleLoops(int d, Points* flat, double* achieved) const {
  for (int g = 0; g < num_groups_; ++g) {
    for (int i = 0; i < static_cast<int>(breaks_[g].size()); ++i) {
      const int gi = interval_start_[g] + i;
      const double t1 = IntervalEnd(g, i);
      for (int k = 0; k < count_[gi]; ++k) {
        const double a0 = param(d, g).Forward(interval_t_[gi][k]);
        (*flat)[first_vertex_[gi] + k] = curve(d, g).At(a0);
        const double a1 = param(d, g).Forward(k + 1 < count_[gi] ? interval_t_[gi][k + 1] : t1);
        double far;
        *achieved = std::max(*achieved, ChordDeviation(curve(d, g), a0, a1, &far) / scale(d));
      }
    }
  }
}

// Collocates the two sides of each cut/opening of drawing d exactly (positions copied from the
// lower interval) and pairs their edges.
void CompatibleSampling::CollocateTwins(int d, Points* flat, std::vector<int>* edge_twin) const {
  Points& p = *flat;
  for (int gi = 0; gi < interval_start_.back(); ++gi) {
    const int gj = twin_interval_[d][gi];
    if (gj < 0) continue;
    const int n = count_[gi];
    for (int k = 0; k < n; ++k)
      (*edge_twin)[first_vertex_[gi] + k] = first_vertex_[gj] + (n - 1 - k);
    if (gi > gj) continue;
    for (int k = 1; k < n; ++k) p[first_vertex_[gj] + (n - k)] = p[first_vertex_[gi] + k];
    p[first_vertex_[NextInLoop(gj)]] = p[first_vertex_[gi]];
    p[first_vertex_[gj]] = p[first_vertex_[NextInLoop(gi)]];
  }
}

// Each mark's breakpoint (the nearest one: AddBreak kept an earlier breakpoint within kSameT
// instead of a second one) starts an interval; its first vertex is the mark's.
void CompatibleSampling::FindMarkVertices(std::vector<int>* mark_vertices) const {
  for (int g = 0; g < num_groups_; ++g) {
    const std::vector<double>& b = breaks_[g];
    for (const auto& [at0, unused] : param_.marks[g]) {
      const double t = Wrap01((at0 - param_.marks[g][0].first) / curve(0, g).length());
      int nearest = 0;
      double best = 2.0;
      for (size_t i = 0; i < b.size(); ++i) {
        const double gap = std::abs(b[i] - t);
        const double dist = std::min(gap, 1.0 - gap);
        if (dist < best) best = dist, nearest = static_cast<int>(i);
      }
      mark_vertices->push_back(first_vertex_[interval_start_[g] + nearest]);
    }
  }
  std::sort(mark_vertices->begin(), mark_vertices->end());
  mark_vertices->erase(std::unique(mark_vertices->begin(), mark_vertices->end()),
                       mark_vertices->end());
}

void CompatibleSampling::Sample(BoundaryCorrespondence* out) {
  UnionFind classes = LinkTwinIntervals();
  CountVertices(&classes);
  const int num_intervals = interval_start_.back();
  for (int i = 0; i < num_intervals; ++i) out->base_vertices += count_[i];
  RefineTwinClasses(&classes);
  PlaceVertices();
  // Vertex numbering: intervals in order, loop by loop.
  first_vertex_.assign(num_intervals + 1, 0);
  for (int i = 0; i < num_intervals; ++i) first_vertex_[i + 1] = first_vertex_[i] + count_[i];
  out->loop_start.resize(num_groups_ + 1);
  for (int g = 0; g <= num_groups_; ++g) out->loop_start[g] = first_vertex_[interval_start_[g]];
  const int num_vertices = first_vertex_.back();
  out->shapes.assign(num_shapes_, std::vector<Points>(num_groups_));
  out->edge_twin.assign(num_shapes_, std::vector<int>(num_vertices, -1));
  for (int d = 0; d < num_shapes_; ++d) {
    Points flat(num_vertices);
    SampleLoops(d, &flat, &out->achieved_tolerance);
    CollocateTwins(d, &flat, &out->edge_twin[d]);
    for (int g = 0; g < num_groups_; ++g) {
      out->shapes[d][g].assign(flat.begin() + out->loop_start[g],
                               flat.begin() + out->loop_start[g + 1]);
    }
  }
  FindMarkVertices(&out->mark_vertices);
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
  return WithReason(absl::InvalidArgumentError(message), kReasonTopologyDiffers);
}

absl::StatusOr<BoundaryCorrespondence> ComputeBoundaryCorrespondence(
    const std::vector<BoundaryGraph>& graphs, const BoundaryCorrespondenceOptions& options) {
  if (graphs.empty()) return absl::InvalidArgumentError("no drawings");
  if (absl::Status s = CheckSameEquivalence(graphs); !s.ok()) return s;
  const boundary_internal::NormalisedLoops normalised = boundary_internal::NormaliseLoops(graphs);
  absl::StatusOr<boundary_internal::LoopGroups> groups =
      boundary_internal::MatchLoopGroups(graphs, normalised, options.marks);
  if (!groups.ok()) return groups.status();
  const GroupedLoops loops{normalised, *groups};
  absl::StatusOr<Parameterization> param = boundary_internal::ParameterizeGroups(loops, options);
  if (!param.ok()) return param.status();
  CompatibleSampling sampling(graphs, loops, *param, options);
  if (absl::Status s = sampling.FindBreakpoints(); !s.ok()) return s;
  BoundaryCorrespondence out;
  out.loop_outer = groups->outer;
  out.loop_component = groups->component;
  out.corner_matched_loops = param->corner_matched_loops;
  sampling.Sample(&out);
  return out;
}

}  // namespace inbetween::solver
