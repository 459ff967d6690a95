// Auto-topology proposals (see auto_topology.h): shortest inside cuts from extra holes to their
// component's outline.
#include "solver/geometry/auto_topology.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "solver/geometry/polygon.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/cgal_predicates.h"

namespace inbetween::solver {
namespace {

struct Segment {
  Point a, b;
};

// The point of the closed loop nearest to p.
Point NearestOnLoop(const Point& p, const Points& loop) {
  Point best = loop[0];
  double best_d2 = (p - best).squaredNorm();
  for (size_t i = 0; i < loop.size(); ++i) {
    const Point q = NearestOnSegment(p, loop[i], loop[(i + 1) % loop.size()]);
    const double d2 = (p - q).squaredNorm();
    if (d2 < best_d2) best_d2 = d2, best = q;
  }
  return best;
}

// True when the open segment p-q meets no obstacle (its end points lie on boundaries, so a tiny
// piece at each end is left out) and its midpoint is inside the component: inside the outer
// loop, outside every hole.
bool CutStaysInside(const Point& p, const Point& q, const std::vector<Segment>& obstacles,
                    const Points& outer, const std::vector<const Points*>& holes) {
  const Point d = q - p;
  if (d.squaredNorm() == 0) return false;
  constexpr double kTrim = 1e-7;
  const Point p1 = p + kTrim * d, q1 = q - kTrim * d;
  for (const Segment& s : obstacles) {
    if (ExactSegmentContact(p1, q1, s.a, s.b).kind != SegmentContact::kNone) return false;
  }
  const Point mid = 0.5 * (p + q);
  if (!PolygonContains(outer, mid)) return false;
  for (const Points* h : holes) {
    if (PolygonContains(*h, mid)) return false;
  }
  return true;
}

// Component ids of `graph` ordered by hole count (descending, then id), as EquivalenceClass
// orders holes_per_component; plus the hole loops of each component.
struct Components {
  std::vector<int> by_rank;
  std::vector<std::vector<int>> hole_loops;  // per component id
  std::vector<int> outer_loop;               // per component id
};

Components ComponentsOf(const BoundaryGraph& graph) {
  Components c;
  const int n = graph.equivalence.components;
  c.hole_loops.resize(n);
  c.outer_loop.assign(n, -1);
  for (int l = 0; l < static_cast<int>(graph.loops.size()); ++l) {
    const BoundaryLoop& loop = graph.loops[l];
    if (loop.component < 0 || loop.component >= n) continue;
    if (loop.outer) {
      c.outer_loop[loop.component] = l;
    } else {
      c.hole_loops[loop.component].push_back(l);
    }
  }
  c.by_rank.resize(n);
  std::iota(c.by_rank.begin(), c.by_rank.end(), 0);
  std::stable_sort(c.by_rank.begin(), c.by_rank.end(),
                   [&](int a, int b) { return c.hole_loops[a].size() > c.hole_loops[b].size(); });
  return c;
}

// The shortest cut from hole loop `hole` to outer loop `outer` that stays inside, or nullopt.
std::optional<Segment> ShortestCut(const Points& hole, const Points& outer,
                                   const std::vector<Segment>& obstacles,
                                   const std::vector<const Points*>& holes,
                                   const AutoTopologyOptions& options) {
  // Edge midpoints first, so that among equally short cuts (parallel edges) the stable sort
  // keeps one from the middle of an edge rather than from a corner.
  std::vector<std::pair<double, Segment>> candidates;
  for (size_t i = 0; i < hole.size(); ++i) {
    const Point h = 0.5 * (hole[i] + hole[(i + 1) % hole.size()]);
    const Point o = NearestOnLoop(h, outer);
    candidates.push_back({(o - h).squaredNorm(), {h, o}});
  }
  for (const Point& h : hole) {
    const Point o = NearestOnLoop(h, outer);
    candidates.push_back({(o - h).squaredNorm(), {h, o}});
  }
  for (const Point& o : outer) {
    const Point h = NearestOnLoop(o, hole);
    candidates.push_back({(o - h).squaredNorm(), {h, o}});
  }
  const auto by_length = [](const auto& x, const auto& y) { return x.first < y.first; };
  std::stable_sort(candidates.begin(), candidates.end(), by_length);
  for (const auto& [unused, s] : candidates) {
    if (CutStaysInside(s.a, s.b, obstacles, outer, holes)) return s;
  }
  // Something is in the way of every nearest-point cut: try vertex pairs, shortest first.
  candidates.clear();
  for (const Point& h : hole) {
    for (const Point& o : outer) candidates.push_back({(o - h).squaredNorm(), {h, o}});
  }
  const size_t keep = std::min(candidates.size(), static_cast<size_t>(options.max_pair_candidates));
  std::partial_sort(candidates.begin(), candidates.begin() + keep, candidates.end(), by_length);
  for (size_t i = 0; i < keep; ++i) {
    if (CutStaysInside(candidates[i].second.a, candidates[i].second.b, obstacles, outer, holes)) {
      return candidates[i].second;
    }
  }
  return std::nullopt;
}

// The cut drawn the way docs/svg-convention.md asks for: crossing the boundary at both ends (the
// builder clips the overhang), so an end point that rounding put a hair inside the shape still
// reaches the boundary. The overhang is 1% of the cut, less if that would leave the hole or
// re-enter the shape; an end whose overhang cannot be placed (a slit hole) stays on the boundary.
template <class OutsideShape>
Point Overhang(const Point& end, const Point& direction, double length, OutsideShape outside) {
  for (double step = 0.01 * length, i = 0; i < 8; ++i, step /= 4) {
    if (outside(end + step * direction)) return end + step * direction;
  }
  return end;
}

Points CrossBothEnds(const Segment& cut, const Points& hole, const Points& outer) {
  const Point u = (cut.b - cut.a).normalized();
  const double length = (cut.b - cut.a).norm();
  return {Overhang(cut.a, -u, length, [&](const Point& p) { return PolygonContains(hole, p); }),
          Overhang(cut.b, u, length, [&](const Point& p) { return !PolygonContains(outer, p); })};
}

// A chord of a component's outer loop: both ends overhang outwards.
Points CrossOutline(const Segment& cut, const Points& outer) {
  const Point u = (cut.b - cut.a).normalized();
  const double length = (cut.b - cut.a).norm();
  const auto outside = [&](const Point& p) { return !PolygonContains(outer, p); };
  return {Overhang(cut.a, -u, length, outside), Overhang(cut.b, u, length, outside)};
}

// The shortest straight chord across component `c` of `g` (its largest by outer area) that stays
// inside and leaves at least `min_part` of the component's outer area on each side: the
// narrowest neck, where a shape that becomes two pieces in another drawing most likely parts.
std::optional<Segment> SplitCut(const BoundaryGraph& g, int outer_loop,
                                const std::vector<const Points*>& holes,
                                const std::vector<Segment>& obstacles, double min_part,
                                const AutoTopologyOptions& options) {
  const Points& loop = g.loops[outer_loop].points;
  Points q;  // vertices and edge midpoints, thinned to at most kMaxPoints
  for (size_t i = 0; i < loop.size(); ++i) {
    q.push_back(loop[i]);
    q.push_back(0.5 * (loop[i] + loop[(i + 1) % loop.size()]));
  }
  constexpr size_t kMaxPoints = 400;
  if (q.size() > kMaxPoints) {
    const size_t stride = (q.size() + kMaxPoints - 1) / kMaxPoints;
    Points thin;
    for (size_t i = 0; i < q.size(); i += stride) thin.push_back(q[i]);
    q = std::move(thin);
  }
  const size_t m = q.size();
  std::vector<double> prefix(m + 1, 0.0);  // prefix[k] = sum of Cross(q_i, q_i+1), i < k
  for (size_t i = 0; i < m; ++i) prefix[i + 1] = prefix[i] + Cross(q[i], q[(i + 1) % m]);
  const double total = 0.5 * prefix[m];
  if (!(total > 0)) return std::nullopt;
  std::vector<std::pair<double, std::pair<int, int>>> chords;
  for (size_t i = 0; i < m; ++i) {
    for (size_t j = i + 2; j < m; ++j) {
      const double part = 0.5 * (prefix[j] - prefix[i] + Cross(q[j], q[i]));
      if (std::min(part, total - part) < min_part * total) continue;
      chords.push_back({(q[j] - q[i]).squaredNorm(), {static_cast<int>(i), static_cast<int>(j)}});
    }
  }
  const size_t keep = std::min(chords.size(), static_cast<size_t>(options.max_pair_candidates));
  std::partial_sort(chords.begin(), chords.begin() + keep, chords.end(),
                    [](const auto& x, const auto& y) { return x.first < y.first; });
  for (size_t k = 0; k < keep; ++k) {
    const Point& a = q[chords[k].second.first];
    const Point& b = q[chords[k].second.second];
    if (CutStaysInside(a, b, obstacles, loop, holes)) return Segment{a, b};
  }
  return std::nullopt;
}

std::vector<Segment> LoopSegments(const BoundaryGraph& g) {
  std::vector<Segment> out;
  for (const BoundaryLoop& loop : g.loops) {
    for (size_t i = 0; i < loop.points.size(); ++i) {
      out.push_back({loop.points[i], loop.points[(i + 1) % loop.points.size()]});
    }
  }
  return out;
}

// Splits drawing d (its graph `*g`) at its narrowest necks, largest piece first, until it has
// `num_components` pieces; the cuts and notes go to `result`. `most` is the drawing with the most
// pieces (named in the error when no straight cut splits a piece).
absl::Status SplitToComponents(size_t d, const Drawing& drawing, int num_components, size_t most,
                               const BoundaryGraph& most_graph, const AutoTopologyOptions& options,
                               BoundaryGraph* g, AutoTopologyResult* result) {
  Drawing edited = drawing;
  while (g->equivalence.components < num_components) {
    const Components comps = ComponentsOf(*g);
    int largest = -1;
    double largest_area = 0;
    for (int c = 0; c < g->equivalence.components; ++c) {
      if (comps.outer_loop[c] < 0) continue;
      const double area = PolygonSignedArea(g->loops[comps.outer_loop[c]].points);
      if (largest < 0 || area > largest_area) largest = c, largest_area = area;
    }
    std::vector<const Points*> holes;
    std::optional<Segment> cut;
    if (largest >= 0) {
      for (int h : comps.hole_loops[largest]) holes.push_back(&g->loops[h].points);
      cut = SplitCut(*g, comps.outer_loop[largest], holes, LoopSegments(*g), options.min_split_part,
                     options);
    }
    if (!cut) {
      return absl::FailedPreconditionError(absl::StrCat(
          "auto-topology: drawing ", d + 1, " has ", g->equivalence.ToString(), ", drawing ",
          most + 1, " has ", most_graph.equivalence.ToString(),
          "; no straight cut splits a piece of drawing ", d + 1,
          " into two parts: draw a cut (a polyline across it) in its \"cuts\" in the project "
          "file"));
    }
    Points drawn = CrossOutline(*cut, g->loops[comps.outer_loop[largest]].points);
    edited.cuts.push_back(drawn);
    result->cuts[d].push_back(std::move(drawn));
    result->notes.push_back(absl::StrFormat(
        "drawing %d: cut across the piece from (%.6g, %.6g) to (%.6g, %.6g), length %.6g", d + 1,
        cut->a.x(), cut->a.y(), cut->b.x(), cut->b.y(), (cut->b - cut->a).norm()));
    const int before = g->equivalence.components;
    absl::StatusOr<BoundaryGraph> rebuilt = BuildBoundaries(edited, static_cast<int>(d) + 1);
    if (!rebuilt.ok() || rebuilt->equivalence.components <= before) {
      return absl::InternalError(absl::StrCat(
          "auto-topology: the cut proposed to split drawing ", d + 1, " does not split it (",
          rebuilt.ok() ? rebuilt->equivalence.ToString() : rebuilt.status().message(), ")"));
    }
    *g = *std::move(rebuilt);
  }
  return absl::OkStatus();
}

// The class every drawing can reach by cutting holes open: the split drawings' components, per
// component rank as many holes as the drawing with fewest there.
EquivalenceClass TargetClass(const std::vector<BoundaryGraph>& graphs, size_t most,
                             int num_components) {
  EquivalenceClass target = graphs[most].equivalence;
  for (int k = 0; k < num_components; ++k) {
    for (const BoundaryGraph& g : graphs) {
      target.holes_per_component[k] =
          std::min(target.holes_per_component[k], g.equivalence.holes_per_component[k]);
    }
  }
  target.holes =
      std::accumulate(target.holes_per_component.begin(), target.holes_per_component.end(), 0);
  return target;
}

// Cuts drawing d's extra holes open (the smallest first, per component rank) to reach
// result->target, then checks the proposal the way the multimesh builder will read it.
absl::Status OpenExtraHoles(size_t d, const Drawing& drawing, const BoundaryGraph& g,
                            int num_components, const AutoTopologyOptions& options,
                            AutoTopologyResult* result) {
  const Components comps = ComponentsOf(g);
  std::vector<Segment> obstacles = LoopSegments(g);
  for (int k = 0; k < num_components; ++k) {
    const int c = comps.by_rank[k];
    std::vector<int> holes = comps.hole_loops[c];
    const int extra = static_cast<int>(holes.size()) - result->target.holes_per_component[k];
    if (extra <= 0) continue;
    // The smallest holes are the ones the other drawings lack most likely (a hole that opens).
    std::stable_sort(holes.begin(), holes.end(), [&](int a, int b) {
      return std::abs(PolygonSignedArea(g.loops[a].points)) <
             std::abs(PolygonSignedArea(g.loops[b].points));
    });
    std::vector<const Points*> hole_points;
    for (int h : comps.hole_loops[c]) hole_points.push_back(&g.loops[h].points);
    const Points& outer = g.loops[comps.outer_loop[c]].points;
    for (int i = 0; i < extra; ++i) {
      const Points& hole = g.loops[holes[i]].points;
      std::optional<Segment> cut = ShortestCut(hole, outer, obstacles, hole_points, options);
      if (!cut) {
        const Point at = hole[0];
        return absl::FailedPreconditionError(absl::StrFormat(
            "auto-topology: drawing %d: no straight cut from the hole at (%.6g, %.6g) to the "
            "outline stays inside the shape; draw one (a polyline) in the project file's "
            "\"cuts\" of drawing %d",
            d + 1, at.x(), at.y(), d + 1));
      }
      obstacles.push_back(*cut);
      result->cuts[d].push_back(CrossBothEnds(*cut, hole, outer));
      result->notes.push_back(absl::StrFormat(
          "drawing %d: cut from the hole at (%.6g, %.6g) to the outline at (%.6g, %.6g), "
          "length %.6g",
          d + 1, cut->a.x(), cut->a.y(), cut->b.x(), cut->b.y(), (cut->b - cut->a).norm()));
    }
  }
  Drawing edited = drawing;
  for (const Points& cut : result->cuts[d]) edited.cuts.push_back(cut);
  absl::StatusOr<BoundaryGraph> rebuilt = BuildBoundaries(edited, static_cast<int>(d) + 1);
  if (!rebuilt.ok()) {
    return absl::InternalError(absl::StrCat("auto-topology: the proposed cuts of drawing ", d + 1,
                                            " do not apply: ", rebuilt.status().message()));
  }
  if (!(rebuilt->equivalence == result->target)) {
    return absl::InternalError(
        absl::StrCat("auto-topology: drawing ", d + 1, " has ", rebuilt->equivalence.ToString(),
                     " after the proposed cuts, expected ", result->target.ToString(), " (",
                     absl::StrJoin(result->notes, "; "), ")"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<AutoTopologyResult> ProposeTopology(const std::vector<Drawing>& drawings,
                                                   const AutoTopologyOptions& options) {
  if (drawings.empty()) return absl::InvalidArgumentError("auto-topology: no drawings");
  std::vector<BoundaryGraph> graphs;
  for (size_t d = 0; d < drawings.size(); ++d) {
    absl::StatusOr<BoundaryGraph> g = BuildBoundaries(drawings[d], static_cast<int>(d) + 1);
    if (!g.ok()) return g.status();
    graphs.push_back(*std::move(g));
  }
  AutoTopologyResult result;
  result.cuts.resize(drawings.size());

  // 1. Components: a drawing with fewer pieces than another is split at its narrowest necks.
  int num_components = 0;
  size_t most = 0;
  for (size_t d = 0; d < graphs.size(); ++d) {
    if (graphs[d].equivalence.components > num_components) {
      num_components = graphs[d].equivalence.components, most = d;
    }
  }
  for (size_t d = 0; d < graphs.size(); ++d) {
    if (absl::Status s = SplitToComponents(d, drawings[d], num_components, most, graphs[most],
                                           options, &graphs[d], &result);
        !s.ok()) {
      return s;
    }
  }

  // 2. Holes, per component rank.
  result.target = TargetClass(graphs, most, num_components);
  for (size_t d = 0; d < graphs.size(); ++d) {
    if (graphs[d].equivalence == result.target) continue;
    if (absl::Status s =
            OpenExtraHoles(d, drawings[d], graphs[d], num_components, options, &result);
        !s.ok()) {
      return s;
    }
  }
  return result;
}

}  // namespace inbetween::solver
