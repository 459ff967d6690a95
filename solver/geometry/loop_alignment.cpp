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

}  // namespace

LoopAlignment AlignLoops(const Points& a_loop, const Points& b_loop, double hint,
                         const LoopAlignmentOptions& options) {
  const Sampled sa = SampleLoop(a_loop, options);
  const Sampled sb = SampleLoop(b_loop, options);
  const int m = static_cast<int>(sa.s.size()), n = static_cast<int>(sb.s.size());
  // a's start: its most turning sample (the earliest of equals).
  int a0 = 0;
  for (int i = 1; i < m; ++i) {
    if (std::abs(sa.turn[i]) > std::abs(sa.turn[a0]) + 1e-12) a0 = i;
  }
  auto ia = [&](int i) { return (a0 + i) % m; };
  std::vector<double> ua(m + 1);  // a's arc fraction from its start
  for (int i = 0; i < m; ++i) {
    double s = sa.s[ia(i)] - sa.s[a0];
    if (s < 0) s += sa.length;
    ua[i] = s / sa.length;
  }
  ua[m] = 1.0;

  // Starts on b.
  std::vector<int> starts;
  auto add_start = [&](int j) {
    j = ((j % n) + n) % n;
    if (static_cast<int>(starts.size()) < options.max_starts &&
        std::find(starts.begin(), starts.end(), j) == starts.end()) {
      starts.push_back(j);
    }
  };
  int hint_j = 0;
  {
    double h = std::fmod(hint * sb.length, sb.length);
    if (h < 0) h += sb.length;
    double best = kInf;
    for (int j = 0; j < n; ++j) {
      const double gap = std::abs(sb.s[j] - h);
      const double d = std::min(gap, sb.length - gap);
      if (d < best) best = d, hint_j = j;
    }
  }
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

  const int step = std::max(1, options.max_step);
  const int width = n + 1;
  std::vector<double> cost((m + 1) * width);
  std::vector<uint8_t> back((m + 1) * width);
  std::vector<uint8_t> best_back;
  int best_start = -1;
  double best_cost = kInf;
  std::vector<double> ub(n + 1);
  // Squared turns, for the samples a step skips.
  for (const int j0 : starts) {
    for (int j = 0; j < n; ++j) {
      double s = sb.s[(j0 + j) % n] - sb.s[j0];
      if (s < 0) s += sb.length;
      ub[j] = s / sb.length;
    }
    ub[n] = 1.0;
    auto jb = [&](int j) { return (j0 + j) % n; };
    std::fill(cost.begin(), cost.end(), kInf);
    cost[0] = 0.0;
    for (int i = 0; i < m; ++i) {
      // Costs only grow along a path, and every path to the end passes through one of rows
      // i .. i + step - 1 (whose cells rows before i have all reached): once none of them holds
      // a cell below the best start's total, this start cannot win (the result is the same; a
      // bad start is left after a few rows).
      double row_min = kInf;
      for (int r = i; r < std::min(m + 1, i + step); ++r) {
        for (int j = 0; j <= n; ++j) row_min = std::min(row_min, cost[r * width + j]);
      }
      if (!(row_min < best_cost)) break;
      for (int j = 0; j < n; ++j) {
        const double here = cost[i * width + j];
        if (here == kInf) continue;
        double skipped_a = 0.0;
        for (int di = 1; di <= step && i + di <= m; ++di) {
          const int i1 = i + di;
          const double la = ua[i1] - ua[i];
          const Point& pa = sa.p[ia(i1)];
          const double ta = sa.turn[ia(i1)];
          double skipped_b = 0.0;
          for (int dj = 1; dj <= step && j + dj <= n; ++dj) {
            const int j1 = j + dj;
            // Both ends of the loops are reached together (the path closes on the start pair).
            if ((i1 == m) != (j1 == n)) {
              skipped_b += sb.turn[jb(j1)] * sb.turn[jb(j1)];
              continue;
            }
            if (std::abs(ub[j1] - ua[i1]) > options.band && j1 != n) {
              skipped_b += sb.turn[jb(j1)] * sb.turn[jb(j1)];
              continue;
            }
            const double lb = ub[j1] - ub[j];
            const double tb = sb.turn[jb(j1)];
            const double stretch = (la - lb) * (la - lb) / (la + lb);
            const double turn = (ta - tb) * (ta - tb) + skipped_a + skipped_b;
            const double position = (pa - sb.p[jb(j1)]).squaredNorm() * 0.5 * (la + lb);
            const double c = here + options.stretch_weight * stretch + options.turn_weight * turn +
                             options.position_weight * position;
            double& there = cost[i1 * width + j1];
            if (c < there) there = c, back[i1 * width + j1] = static_cast<uint8_t>(di * 16 + dj);
            skipped_b += tb * tb;
          }
          skipped_a += ta * ta;
        }
      }
    }
    const double total = cost[m * width + n];
    if (total < best_cost) best_cost = total, best_start = j0, best_back = back;
  }
  LoopAlignment out;
  if (best_start < 0) {  // no path within the band (cannot happen with the hint's diagonal)
    out.a = {0.0};
    out.b = {hint - std::floor(hint)};
    out.cost = kInf;
    return out;
  }
  out.cost = best_cost;
  // The path, as unwrapped arcs from a's and b's starts.
  std::vector<std::pair<double, double>> path;  // (arc on a, arc on b), unwrapped
  {
    std::vector<double> ubest(n + 1);
    for (int j = 0; j < n; ++j) {
      double s = sb.s[(best_start + j) % n] - sb.s[best_start];
      if (s < 0) s += sb.length;
      ubest[j] = s / sb.length;
    }
    ubest[n] = 1.0;
    int i = m, j = n;
    while (i > 0 || j > 0) {
      path.push_back({sa.s[a0] + ua[i] * sa.length, sb.s[best_start] + ubest[j] * sb.length});
      const uint8_t code = best_back[i * width + j];
      i -= code / 16, j -= code % 16;
    }
    path.push_back({sa.s[a0], sb.s[best_start]});
    std::reverse(path.begin(), path.end());  // from (a0, b0) to (a0 + length, b0 + length)
  }
  // Only the pairs where either loop turns (kKnotDegrees in the sample's window) are kept as
  // knots: between them the correspondence is linear in both arc lengths, so the DP's staircase
  // of 1..max_step steps on a straight side or a gentle curve does not show, and a polygon and
  // its affine copy correspond exactly (by arc length between matched corners).
  {
    const double knot = kKnotDegrees * M_PI / 180.0;
    std::vector<std::pair<double, double>> kept;
    for (size_t k = 0; k < path.size(); ++k) {
      const double arc_a = path[k].first, arc_b = path[k].second;
      double fa = std::fmod(arc_a, sa.length), fb = std::fmod(arc_b, sb.length);
      auto turn_at = [](const Sampled& s, double arc) {
        const auto it = std::lower_bound(s.s.begin(), s.s.end(), arc - 1e-12 * s.length);
        const size_t i = it == s.s.end() ? 0 : static_cast<size_t>(it - s.s.begin());
        return std::abs(s.turn[i]);
      };
      if (k == 0 || k + 1 == path.size() || turn_at(sa, fa) > knot || turn_at(sb, fb) > knot) {
        kept.push_back(path[k]);
      }
    }
    path = std::move(kept);
  }
  // Re-based so that a starts at arc 0: b at a's arc length `length a` (unwrapped), then the
  // pairs past it (a - length a), then those before it (b + length b).
  const double la = sa.length;
  double b_star = path.front().second;
  if (sa.s[a0] > 0.0) {
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      if (path[k].first <= la && la <= path[k + 1].first) {
        const double f = (la - path[k].first) / (path[k + 1].first - path[k].first);
        b_star = path[k].second + f * (path[k + 1].second - path[k].second);
        break;
      }
    }
  }
  out.a.push_back(0.0);
  out.b.push_back(b_star);
  if (sa.s[a0] > 0.0) {
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      if (path[k].first > la) out.a.push_back(path[k].first - la), out.b.push_back(path[k].second);
    }
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      if (path[k].first < la) {
        out.a.push_back(path[k].first), out.b.push_back(path[k].second + sb.length);
      }
    }
  } else {
    for (size_t k = 1; k + 1 < path.size(); ++k) {
      out.a.push_back(path[k].first), out.b.push_back(path[k].second);
    }
  }
  const double shift = std::floor(out.b[0] / sb.length) * sb.length;
  for (double& a : out.a) a /= sa.length;
  for (double& b : out.b) b = (b - shift) / sb.length;
  return out;
}

}  // namespace inbetween::solver
