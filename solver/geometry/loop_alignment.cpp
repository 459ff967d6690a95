// Feature alignment of two closed loops by dynamic programming over their samples (see the
// header for the cost). Each start pairs a's most turning sample with one of b's; for each, a
// banded DP over (sample of a, sample of b) with steps of 1..max_step samples in both finds the
// cheapest monotone path once round both loops; the cheapest start wins (ties: the earliest
// tried, so the result is deterministic).
#include "solver/geometry/loop_alignment.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "solver/geometry/primitives.h"
#include "solver/geometry/resample_outline.h"

namespace inbetween::solver {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Matched samples where neither loop turns by more than this (degrees, in the sample's window)
// are not kept as knots of the correspondence.
constexpr double kKnotDegrees = 5.0;

struct Sampled {
  std::vector<double> s;     // arc length, increasing, in [0, length)
  Points p;                  // positions
  std::vector<double> turn;  // the loop's turning within the sample's window (radians, signed)
  double length = 0;
};

double TurnAt(const Points& p, int i) {
  const int n = static_cast<int>(p.size());
  const Point a = p[i] - p[(i + n - 1) % n], b = p[(i + 1) % n] - p[i];
  return std::atan2(Cross(a, b), a.dot(b));
}

// Corners of `loop` and points spread by arc length (module doc of the header), with each
// sample's window turning: the turns of the loop's vertices between the midpoints to its
// neighbouring samples.
Sampled SampleLoop(const Points& loop, const LoopAlignmentOptions& options) {
  const int n = static_cast<int>(loop.size());
  const std::vector<double> cum = CumulativeLength(loop);
  Sampled out;
  out.length = cum[n];
  const std::vector<int> corners = FindCorners(loop, options.corner_angle_degrees);
  const int spread = std::max(3, options.max_samples - static_cast<int>(corners.size()));
  const double spacing = out.length / spread;
  std::vector<double> arcs;
  for (int c : corners) arcs.push_back(cum[c]);
  for (int k = 0; k < spread; ++k) {
    const double s = out.length * k / spread;
    bool near = false;
    for (int c : corners) {
      const double gap = std::abs(cum[c] - s);
      near = near || std::min(gap, out.length - gap) < 0.25 * spacing;
    }
    if (!near) arcs.push_back(s);
  }
  std::sort(arcs.begin(), arcs.end());
  arcs.erase(std::unique(arcs.begin(), arcs.end()), arcs.end());
  const int m = static_cast<int>(arcs.size());
  out.s = arcs;
  out.turn.assign(m, 0.0);
  // Window boundaries: midpoints between consecutive samples; window i is [mid[i], mid[i + 1]).
  std::vector<double> mid(m);
  for (int i = 0; i < m; ++i) {
    const double prev = i > 0 ? arcs[i - 1] : arcs[m - 1] - out.length;
    mid[i] = 0.5 * (prev + arcs[i]);
  }
  size_t seg = 0;
  for (int i = 0; i < m; ++i) {
    while (seg + 1 < static_cast<size_t>(n) && cum[seg + 1] <= arcs[i]) ++seg;
    const double len = cum[seg + 1] - cum[seg];
    const double t = len > 0 ? (arcs[i] - cum[seg]) / len : 0.0;
    out.p.push_back(loop[seg] + t * (loop[(seg + 1) % n] - loop[seg]));
  }
  for (int k = 0; k < n; ++k) {
    double s = cum[k];
    if (s < mid[0]) s += out.length;  // mid[0] may be negative: then nothing is below it
    int w = static_cast<int>(std::upper_bound(mid.begin(), mid.end(), s) - mid.begin()) - 1;
    if (w < 0) w = m - 1;
    out.turn[w] += TurnAt(loop, k);
  }
  return out;
}

// a's start: its most turning sample (the earliest of equals).
int MostTurningSample(const Sampled& sa) {
  int a0 = 0;
  for (int i = 1; i < static_cast<int>(sa.s.size()); ++i) {
    if (std::abs(sa.turn[i]) > std::abs(sa.turn[a0]) + 1e-12) a0 = i;
  }
  return a0;
}

// Each sample's arc length from sample `start` (round the loop, in sample order) as a fraction
// of the loop's length; one more entry, 1, closes the loop.
std::vector<double> FractionsFrom(const Sampled& l, int start) {
  const int n = static_cast<int>(l.s.size());
  std::vector<double> u(n + 1);
  for (int j = 0; j < n; ++j) {
    double s = l.s[(start + j) % n] - l.s[start];
    if (s < 0) s += l.length;
    u[j] = s / l.length;
  }
  u[n] = 1.0;
  return u;
}

// The sample of b nearest the fraction `hint` of its arc length.
int NearestSample(const Sampled& sb, double hint) {
  const int n = static_cast<int>(sb.s.size());
  int hint_j = 0;
  double h = std::fmod(hint * sb.length, sb.length);
  if (h < 0) h += sb.length;
  double best = kInf;
  for (int j = 0; j < n; ++j) {
    const double gap = std::abs(sb.s[j] - h);
    const double d = std::min(gap, sb.length - gap);
    if (d < best) best = d, hint_j = j;
  }
  return hint_j;
}

// The samples of b tried as the match of a's start a0, in the order tried, at most
// options.max_starts: the hint's sample; where a's start is a corner, b's samples that turn the
// same way by at least half as much (closest turn first, at most half the starts); the hint's
// neighbours; then samples spread evenly round b from the hint.
std::vector<int> StartsOnB(const Sampled& sa, int a0, const Sampled& sb, double hint,
                           const LoopAlignmentOptions& options) {
  const int n = static_cast<int>(sb.s.size());
  std::vector<int> starts;
  auto add_start = [&](int j) {
    j = ((j % n) + n) % n;
    if (static_cast<int>(starts.size()) < options.max_starts &&
        std::find(starts.begin(), starts.end(), j) == starts.end()) {
      starts.push_back(j);
    }
  };
  const int hint_j = NearestSample(sb, hint);
  add_start(hint_j);
  const double corner = options.corner_angle_degrees * M_PI / 180.0;
  if (std::abs(sa.turn[a0]) > corner) {
    std::vector<std::pair<double, int>> alike;
    for (int j = 0; j < n; ++j) {
      if (sb.turn[j] * sa.turn[a0] > 0 && std::abs(sb.turn[j]) >= 0.5 * std::abs(sa.turn[a0])) {
        alike.push_back({std::abs(sb.turn[j] - sa.turn[a0]), j});
      }
    }
    std::sort(alike.begin(), alike.end());
    for (size_t k = 0; k < alike.size() && static_cast<int>(k) < options.max_starts / 2; ++k) {
      add_start(alike[k].second);
    }
  }
  for (int k : {1, -1, 2, -2, 4, -4}) add_start(hint_j + k);
  const int spread = std::max(1, options.max_starts - static_cast<int>(starts.size()));
  for (int k = 1; k <= spread; ++k)
    add_start(hint_j + static_cast<int>(std::lround(1.0 * k * n / (spread + 1))));
  return starts;
}

// (arc on a, arc on b), unwrapped from a's and b's starts.
using ArcPath = std::vector<std::pair<double, double>>;

// The banded DP of the module comment over cells (i, j): i samples of a and j of b past their
// starts (a's start fixed, b's per Run). The cost and back-pointer tables are reused from start
// to start; a back pointer packs a step's sample counts as di * 16 + dj.
class BandedAlignment {
 public:
  BandedAlignment(const Sampled& sa, const Sampled& sb, int a0, const LoopAlignmentOptions& options)
      : sa_(sa),
        sb_(sb),
        options_(options),
        a0_(a0),
        m_(static_cast<int>(sa.s.size())),
        n_(static_cast<int>(sb.s.size())),
        step_(std::max(1, options.max_step)),
        width_(n_ + 1),
        ua_(FractionsFrom(sa, a0)),
        a_(Rotated(sa, a0)),
        cost_((m_ + 1) * width_),
        row_min_(m_ + 1),
        back_((m_ + 1) * width_) {}

  // The cheapest path's cost from b's start j0, or a value not below `bound` once no path can
  // cost less than `bound` (the best start's so far).
  double Run(int j0, double bound);
  // The back pointers of the last Run.
  const std::vector<uint8_t>& back() const { return back_; }
  // The path recorded in `back` (a Run's back pointers from b's start j0), from (a0, b0) to
  // (a0 + length a, b0 + length b).
  ArcPath Trace(int j0, const std::vector<uint8_t>& back) const;

 private:
  double RowsMin(int i) const;
  void Relax(int i, int j);

  // A loop's samples in path order from a start (index k: the start's k-th successor, k up to
  // the sample count, which is the start again): turn, squared turn, position.
  struct FromStart {
    std::vector<double> turn, turn2;
    Points p;
  };
  static FromStart Rotated(const Sampled& l, int start);

  const Sampled& sa_;
  const Sampled& sb_;
  const LoopAlignmentOptions& options_;
  const int a0_, m_, n_, step_, width_;
  const std::vector<double> ua_;  // a's arc fractions from its start
  const FromStart a_;             // a from its start
  FromStart b_;                   // b from the current Run's start
  std::vector<double> ub_;        // b's arc fractions from the current Run's start
  std::vector<double> cost_, row_min_;
  std::vector<uint8_t> back_;
};

BandedAlignment::FromStart BandedAlignment::Rotated(const Sampled& l, int start) {
  const int n = static_cast<int>(l.s.size());
  FromStart out;
  for (int k = 0; k <= n; ++k) {
    const int i = (start + k) % n;
    out.turn.push_back(l.turn[i]);
    out.turn2.push_back(l.turn[i] * l.turn[i]);
    out.p.push_back(l.p[i]);
  }
  return out;
}

// The least cost in rows i .. i + step - 1. Costs only grow along a path, and every path to the
// end passes through one of these rows (whose cells rows before i have all reached): once none
// holds a cell below the best start's total, this start cannot win (the result is the same; a
// bad start is left after a few rows).
double BandedAlignment::RowsMin(int i) const {
  double rows_min = kInf;
  for (int r = i; r < std::min(m_ + 1, i + step_); ++r) rows_min = std::min(rows_min, row_min_[r]);
  return rows_min;
}

// Every step of 1..step samples of both loops out of cell (i, j), priced as in the header;
// samples a step skips add their squared turns.
void BandedAlignment::Relax(int i, int j) {
  const double here = cost_[i * width_ + j];
  double skipped_a = 0.0;
  for (int di = 1; di <= step_ && i + di <= m_; ++di) {
    const int i1 = i + di;
    const double la = ua_[i1] - ua_[i];
    const Point& pa = a_.p[i1];
    const double ta = a_.turn[i1];
    double skipped_b = 0.0;
    for (int dj = 1; dj <= step_ && j + dj <= n_; ++dj) {
      const int j1 = j + dj;
      // Both ends of the loops are reached together (the path closes on the start pair), and
      // b's sample stays within the band of a's.
      if ((i1 == m_) != (j1 == n_) || (std::abs(ub_[j1] - ua_[i1]) > options_.band && j1 != n_)) {
        skipped_b += b_.turn2[j1];
        continue;
      }
      const double lb = ub_[j1] - ub_[j];
      const double tb = b_.turn[j1];
      const double stretch = (la - lb) * (la - lb) / (la + lb);
      const double turn = (ta - tb) * (ta - tb) + skipped_a + skipped_b;
      const double position = (pa - b_.p[j1]).squaredNorm() * 0.5 * (la + lb);
      const double c = here + options_.stretch_weight * stretch + options_.turn_weight * turn +
                       options_.position_weight * position;
      double& there = cost_[i1 * width_ + j1];
      if (c < there) {
        there = c, back_[i1 * width_ + j1] = static_cast<uint8_t>(di * 16 + dj);
        row_min_[i1] = std::min(row_min_[i1], c);
      }
      skipped_b += b_.turn2[j1];
    }
    skipped_a += a_.turn2[i1];
  }
}

double BandedAlignment::Run(int j0, double bound) {
  ub_ = FractionsFrom(sb_, j0);
  b_ = Rotated(sb_, j0);
  std::fill(cost_.begin(), cost_.end(), kInf);
  std::fill(row_min_.begin(), row_min_.end(), kInf);
  cost_[0] = row_min_[0] = 0.0;
  for (int i = 0; i < m_; ++i) {
    if (!(RowsMin(i) < bound)) break;
    for (int j = 0; j < n_; ++j) {
      // Costs only grow along a path: a cell at or above the bound leads to no cheaper end.
      if (!(cost_[i * width_ + j] < bound)) continue;
      Relax(i, j);
    }
  }
  return cost_[m_ * width_ + n_];
}

ArcPath BandedAlignment::Trace(int j0, const std::vector<uint8_t>& back) const {
  ArcPath path;
  const std::vector<double> ubest = FractionsFrom(sb_, j0);
  int i = m_, j = n_;
  while (i > 0 || j > 0) {
    path.push_back({sa_.s[a0_] + ua_[i] * sa_.length, sb_.s[j0] + ubest[j] * sb_.length});
    const uint8_t code = back[i * width_ + j];
    i -= code / 16, j -= code % 16;
  }
  path.push_back({sa_.s[a0_], sb_.s[j0]});
  std::reverse(path.begin(), path.end());
  return path;
}

// |turn| of the first sample of `s` at or after `arc` (wrapping to sample 0).
double TurnAtOrAfter(const Sampled& s, double arc) {
  const auto it = std::lower_bound(s.s.begin(), s.s.end(), arc - 1e-12 * s.length);
  const size_t i = it == s.s.end() ? 0 : static_cast<size_t>(it - s.s.begin());
  return std::abs(s.turn[i]);
}

// Only the pairs where either loop turns (kKnotDegrees in the sample's window) are kept as
// knots, and the path's ends: between them the correspondence is linear in both arc lengths, so
// the DP's staircase of 1..max_step steps on a straight side or a gentle curve does not show,
// and a polygon and its affine copy correspond exactly (by arc length between matched corners).
ArcPath KeepTurningKnots(const ArcPath& path, const Sampled& sa, const Sampled& sb) {
  const double knot = kKnotDegrees * M_PI / 180.0;
  ArcPath kept;
  for (size_t k = 0; k < path.size(); ++k) {
    const double arc_a = path[k].first, arc_b = path[k].second;
    double fa = std::fmod(arc_a, sa.length), fb = std::fmod(arc_b, sb.length);
    if (k == 0 || k + 1 == path.size() || TurnAtOrAfter(sa, fa) > knot ||
        TurnAtOrAfter(sb, fb) > knot) {
      kept.push_back(path[k]);
    }
  }
  return kept;
}

// The knots re-based so that a starts at arc 0 (a's start sample at arc `start_a`): b at a's
// arc length `length a` (unwrapped), then the pairs past it (a - length a), then those before
// it (b + length b); as fractions of each loop's length, b shifted into [0, 1) at a's 0.
void RebaseOntoA(const ArcPath& path, const Sampled& sa, const Sampled& sb, double start_a,
                 LoopAlignment* out) {
  const double la = sa.length;
  double b_star = path.front().second;
  if (start_a > 0.0) {
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      if (path[k].first <= la && la <= path[k + 1].first) {
        const double f = (la - path[k].first) / (path[k + 1].first - path[k].first);
        b_star = path[k].second + f * (path[k + 1].second - path[k].second);
        break;
      }
    }
  }
  out->a.push_back(0.0);
  out->b.push_back(b_star);
  if (start_a > 0.0) {
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      if (path[k].first > la)
        out->a.push_back(path[k].first - la), out->b.push_back(path[k].second);
    }
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      if (path[k].first < la) {
        out->a.push_back(path[k].first), out->b.push_back(path[k].second + sb.length);
      }
    }
  } else {
    for (size_t k = 1; k + 1 < path.size(); ++k) {
      out->a.push_back(path[k].first), out->b.push_back(path[k].second);
    }
  }
  const double shift = std::floor(out->b[0] / sb.length) * sb.length;
  for (double& a : out->a) a /= sa.length;
  for (double& b : out->b) b = (b - shift) / sb.length;
}

// The starts worth the full DP (StartsOnB, in their order): where there are more than
// kFullStarts, each is first priced by the same DP on both loops sampled kCoarsening times
// more sparsely (corners are kept), and the kFullStarts cheapest go on (ties: the earlier).
// Corners decide the start, and the coarse samples keep every one; the coarse pass costs about
// 1/16 of a full one per start.
std::vector<int> FinestStarts(const Points& a_loop, const Points& b_loop, const Sampled& sa, int a0,
                              const Sampled& sb, double hint, const LoopAlignmentOptions& options) {
  constexpr int kFullStarts = 12, kCoarsening = 4;
  std::vector<int> starts = StartsOnB(sa, a0, sb, hint, options);
  if (static_cast<int>(starts.size()) <= kFullStarts) return starts;
  LoopAlignmentOptions coarse = options;
  coarse.max_samples = std::max(16, options.max_samples / kCoarsening);
  const Sampled ca = SampleLoop(a_loop, coarse), cb = SampleLoop(b_loop, coarse);
  // a's start on the coarse loop: the coarse sample nearest a's start.
  const int ca0 = NearestSample(ca, sa.s[a0] / sa.length);
  BandedAlignment dp(ca, cb, ca0, coarse);
  std::vector<std::pair<double, int>> priced;  // (coarse cost, position in `starts`)
  double bound = kInf;                         // the kFullStarts-th cheapest so far
  for (size_t k = 0; k < starts.size(); ++k) {
    const double cost = dp.Run(NearestSample(cb, sb.s[starts[k]] / sb.length), bound);
    priced.push_back({cost, static_cast<int>(k)});
    if (static_cast<int>(priced.size()) >= kFullStarts) {
      std::vector<double> costs;
      for (const auto& [c, unused] : priced) costs.push_back(c);
      std::nth_element(costs.begin(), costs.begin() + kFullStarts - 1, costs.end());
      bound = costs[kFullStarts - 1];
    }
  }
  std::stable_sort(priced.begin(), priced.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<int> keep;
  for (int k = 0; k < kFullStarts; ++k) keep.push_back(priced[k].second);
  std::sort(keep.begin(), keep.end());
  std::vector<int> out;
  for (int k : keep) out.push_back(starts[k]);
  return out;
}

}  // namespace

LoopAlignment AlignLoops(const Points& a_loop, const Points& b_loop, double hint,
                         const LoopAlignmentOptions& options) {
  const Sampled sa = SampleLoop(a_loop, options);
  const Sampled sb = SampleLoop(b_loop, options);
  const int a0 = MostTurningSample(sa);
  // The starts' DPs; the cheapest wins (ties: the earliest tried).
  BandedAlignment dp(sa, sb, a0, options);
  std::vector<uint8_t> best_back;
  int best_start = -1;
  double best_cost = kInf;
  for (const int j0 : FinestStarts(a_loop, b_loop, sa, a0, sb, hint, options)) {
    const double total = dp.Run(j0, best_cost);
    if (total < best_cost) best_cost = total, best_start = j0, best_back = dp.back();
  }
  LoopAlignment out;
  if (best_start < 0) {  // no path within the band (cannot happen with the hint's diagonal)
    out.a = {0.0};
    out.b = {hint - std::floor(hint)};
    out.cost = kInf;
    return out;
  }
  out.cost = best_cost;
  RebaseOntoA(KeepTurningKnots(dp.Trace(best_start, best_back), sa, sb), sa, sb, sa.s[a0], &out);
  return out;
}

}  // namespace inbetween::solver
