// S-Alg.1: directed graph flow over the planar straight-line graph of outlines, cuts and
// openings (S-Sec.1 "Equivalence Tool", S-Sec.2, S-Fig.5).
#include "solver/geometry/graph_flow.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "solver/geometry/correspondence.h"
#include "solver/geometry/polygon.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/cgal_predicates.h"

namespace inbetween::solver {
namespace {

std::string Where(const Point& p) { return absl::StrCat("(", p.x(), ", ", p.y(), ")"); }

// Clockwise angle in (0, 2pi] from direction a to direction b (a full turn for b == a).
double ClockwiseAngle(const Point& a, const Point& b) {
  double angle = std::atan2(-Cross(a, b), a.dot(b));
  if (angle <= 0) angle += 2 * M_PI;
  return angle;
}

// A segment of the drawing before splitting.
struct RawSegment {
  Point a, b;
  int kind = 0;  // 0 outline, 1 cut, 2 opening
  int element = 0;
  int index = 0;  // segment index within its element
  std::vector<std::pair<double, Point>> splits;
};

const char* KindName(int kind) { return kind == 0 ? "outline" : kind == 1 ? "cut" : "opening"; }

std::string Name(const RawSegment& s) { return absl::StrCat(KindName(s.kind), " ", s.element + 1); }

}  // namespace

std::string EquivalenceClass::ToString() const {
  std::string out = absl::StrCat(components, components == 1 ? " component, " : " components, ",
                                 holes, holes == 1 ? " hole" : " holes");
  if (components > 1 && holes > 0) {
    std::vector<std::string> parts;
    for (int h : holes_per_component) parts.push_back(absl::StrCat(h));
    absl::StrAppend(&out, " (per component ", absl::StrJoin(parts, "+"), ")");
  }
  return out;
}

absl::StatusOr<GraphFlowResult> DirectedGraphFlow(const Points& nodes,
                                                  const std::vector<GraphEdge>& edges) {
  const int num_nodes = static_cast<int>(nodes.size());
  const int num_half = 2 * static_cast<int>(edges.size());
  auto exists = [&](int h) { return h % 2 == 0 || edges[h / 2].bidirected; };
  auto tail = [&](int h) { return h % 2 == 0 ? edges[h / 2].from : edges[h / 2].to; };
  auto head = [&](int h) { return h % 2 == 0 ? edges[h / 2].to : edges[h / 2].from; };
  std::vector<std::vector<int>> outgoing(num_nodes);
  for (int h = 0; h < num_half; ++h) {
    const GraphEdge& e = edges[h / 2];
    if (e.from < 0 || e.from >= num_nodes || e.to < 0 || e.to >= num_nodes || e.from == e.to) {
      return absl::InvalidArgumentError(absl::StrCat("graph flow: edge ", h / 2, " is invalid"));
    }
    if (exists(h)) outgoing[tail(h)].push_back(h);
  }
  // The clockwise-closest outgoing half-edge after arriving along h.
  auto next = [&](int h) {
    const int v = head(h);
    const Point back = nodes[tail(h)] - nodes[v];
    int best = -1;
    double best_angle = 0;
    for (int g : outgoing[v]) {
      const double angle = ClockwiseAngle(back, nodes[head(g)] - nodes[v]);
      if (best < 0 || angle < best_angle) best = g, best_angle = angle;
    }
    return best;
  };

  GraphFlowResult out;
  out.visits.assign(edges.size(), 0);
  std::vector<bool> used(num_half, false);
  for (int start = 0; start < num_half; ++start) {  // edge_can_be_visited
    if (!exists(start) || used[start]) continue;
    FlowCycle cycle;
    int h = start;
    while (true) {
      cycle.half_edges.push_back(h);
      cycle.nodes.push_back(tail(h));
      used[h] = true;
      ++out.visits[h / 2];
      const int g = next(h);  // next_edge_on_graph
      if (g < 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("the boundary flow cannot close: it stops at ", Where(nodes[head(h)]),
                         " (an outline ends there)"));
      }
      if (g == start) break;  // is_already_in: the cycle is closed
      if (used[g]) {
        return absl::InvalidArgumentError(
            absl::StrCat("the boundary flow cannot close: it runs twice through ",
                         Where(nodes[tail(g)]), " (outlines touch or cross there)"));
      }
      h = g;
    }
    out.cycles.push_back(std::move(cycle));
  }
  return out;
}

// ---- Drawings -> boundaries: BuildBoundaries, phase by phase ----

namespace {

// The drawing's outlines: each checked simple, repeated points dropped (also a closing copy of
// the first), oriented by nesting.
absl::StatusOr<std::vector<Outline>> CleanOutlines(const Drawing& drawing,
                                                   const std::string& what) {
  std::vector<Outline> outlines;
  for (size_t o = 0; o < drawing.outlines.size(); ++o) {
    const std::string name =
        drawing.outlines.size() == 1 ? what : absl::StrCat(what, ", outline ", o + 1);
    if (absl::Status s = CheckSimplePolygon(drawing.outlines[o].points, name); !s.ok()) return s;
    Outline clean;
    for (const Point& p : drawing.outlines[o].points) {
      if (clean.points.empty() || p != clean.points.back()) clean.points.push_back(p);
    }
    while (clean.points.size() > 1 && clean.points.back() == clean.points.front()) {
      clean.points.pop_back();
    }
    outlines.push_back(std::move(clean));
  }
  OrientByNesting(&outlines);
  return outlines;
}

// The distance within which cut and opening ends snap onto an outline
// (BoundaryOptions::snap_relative of the outlines' bounding-box diagonal).
double SnapDistance(const std::vector<Outline>& outlines, const BoundaryOptions& options) {
  Point lo = outlines[0].points[0], hi = lo;
  for (const Outline& o : outlines) {
    for (const Point& p : o.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  return options.snap_relative * (hi - lo).norm();
}

// Every outline's closed sequence of segments, outline by outline.
std::vector<RawSegment> OutlineSegments(const std::vector<Outline>& outlines) {
  std::vector<RawSegment> segments;
  for (size_t o = 0; o < outlines.size(); ++o) {
    const Points& p = outlines[o].points;
    for (size_t i = 0; i < p.size(); ++i) {
      segments.push_back(
          {p[i], p[(i + 1) % p.size()], 0, static_cast<int>(o), static_cast<int>(i), {}});
    }
  }
  return segments;
}

// A cut end p snapped onto the nearest point of the outline segments (the first
// `num_outline_segments`) when within `snap`: onto a segment's start when that is within
// `snap`, so that an end drawn at a corner meets the corner exactly.
Point SnapEnd(const std::vector<RawSegment>& segments, int num_outline_segments, double snap,
              Point p) {
  double best = snap;
  Point snapped = p;
  for (int s = 0; s < num_outline_segments; ++s) {
    const Point a = segments[s].a, d = segments[s].b - a;
    const double t = SegmentParameter(p, a, segments[s].b);
    const Point q = (a - p).squaredNorm() <= snap * snap ? a : a + t * d;
    const double dist = (q - p).norm();
    if (dist > 0 && dist <= best) best = dist, snapped = q;
  }
  return snapped;
}

// The cuts' and then the openings' segments appended after the outlines', repeated points
// dropped and both ends snapped (SnapEnd). INVALID_ARGUMENT for a non-finite point or a line of
// fewer than 2 distinct points.
absl::Status AddLineSegments(const Drawing& drawing, const std::string& what, double snap,
                             std::vector<RawSegment>* segments) {
  const int num_outline_segments = static_cast<int>(segments->size());
  for (int kind : {1, 2}) {
    const std::vector<Points>& lines = kind == 1 ? drawing.cuts : drawing.openings;
    for (size_t c = 0; c < lines.size(); ++c) {
      Points p;
      for (const Point& q : lines[c]) {
        if (!q.allFinite()) {
          return absl::InvalidArgumentError(
              absl::StrCat(what, ", ", KindName(kind), " ", c + 1, " has a non-finite point"));
        }
        if (p.empty() || q != p.back()) p.push_back(q);
      }
      if (p.size() < 2) {
        return absl::InvalidArgumentError(absl::StrCat(what, ", ", KindName(kind), " ", c + 1,
                                                       " needs at least 2 distinct points"));
      }
      p.front() = SnapEnd(*segments, num_outline_segments, snap, p.front());
      p.back() = SnapEnd(*segments, num_outline_segments, snap, p.back());
      for (size_t i = 0; i + 1 < p.size(); ++i) {
        segments->push_back({p[i], p[i + 1], kind, static_cast<int>(c), static_cast<int>(i), {}});
      }
    }
  }
  return absl::OkStatus();
}

// INVALID_ARGUMENT for a contact the graph cannot take: two outlines touching or crossing, a
// line folding back on itself, or a cut or opening running along another line (rather than
// crossing it). Contacts between segments of one outline are not passed here.
absl::Status CheckContact(const std::string& what, const RawSegment& s, const RawSegment& t,
                          const SegmentContact& contact) {
  const bool same_element = s.kind == t.kind && s.element == t.element;
  if (s.kind == 0 && t.kind == 0) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", Name(s), " and ", Name(t),
                                                   " touch or cross at ", Where(contact.point)));
  }
  if (contact.kind == SegmentContact::kOverlap) {
    if (same_element && std::abs(s.index - t.index) == 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ", ", Name(s), " folds back on itself at ", Where(contact.point)));
    }
    const bool s_first = s.kind != 0;
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", Name(s_first ? s : t),
                                                   " runs along ", Name(s_first ? t : s), " at ",
                                                   Where(contact.point),
                                                   "; cuts and openings must cross lines, "
                                                   "not overlap them"));
  }
  return absl::OkStatus();
}

// Pairwise contacts (sweep over x-sorted bounding boxes, exact predicates), recorded as split
// points of both segments. RESOURCE_EXHAUSTED beyond options.max_pair_checks candidate pairs;
// CheckContact's errors.
absl::Status SplitAtContacts(const std::string& what, const BoundaryOptions& options,
                             std::vector<RawSegment>* segments_in) {
  std::vector<RawSegment>& segments = *segments_in;
  const int num_segments = static_cast<int>(segments.size());
  std::vector<int> order(num_segments);
  std::iota(order.begin(), order.end(), 0);
  auto min_x = [&](int i) { return std::min(segments[i].a.x(), segments[i].b.x()); };
  std::sort(order.begin(), order.end(), [&](int l, int r) { return min_x(l) < min_x(r); });
  int64_t pair_checks = 0;
  for (int oi = 0; oi < num_segments; ++oi) {
    RawSegment& s = segments[order[oi]];
    const double max_x = std::max(s.a.x(), s.b.x());
    for (int oj = oi + 1; oj < num_segments && min_x(order[oj]) <= max_x; ++oj) {
      if (options.max_pair_checks > 0 && ++pair_checks > options.max_pair_checks) {
        return absl::ResourceExhaustedError(absl::StrCat(
            what, ": more than ", options.max_pair_checks,
            " pairs of overlapping segments to intersect (many long segments side by side); "
            "simplify the drawing"));
      }
      RawSegment& t = segments[order[oj]];
      if (std::max(s.a.y(), s.b.y()) < std::min(t.a.y(), t.b.y()) ||
          std::max(t.a.y(), t.b.y()) < std::min(s.a.y(), s.b.y())) {
        continue;
      }
      const SegmentContact contact = ExactSegmentContact(s.a, s.b, t.a, t.b);
      if (contact.kind == SegmentContact::kNone) continue;
      const bool same_element = s.kind == t.kind && s.element == t.element;
      if (s.kind == 0 && t.kind == 0 && same_element) continue;  // simple outlines: checked
      if (absl::Status status = CheckContact(what, s, t, contact); !status.ok()) return status;
      s.splits.push_back({contact.t_p, contact.point});
      t.splits.push_back({contact.t_q, contact.point});
    }
  }
  return absl::OkStatus();
}

// A piece of a segment between consecutive split points: graph nodes `from` -> `to`.
struct Piece {
  int from, to, segment;
};

// The graph's nodes (exact coordinates, each once) and every segment's pieces between its
// split points (pieces[s] in order along segment s; zero-length pieces dropped).
struct SplitSegments {
  Points nodes;
  std::vector<std::vector<Piece>> pieces;
};

SplitSegments SplitAtNodes(std::vector<RawSegment>* segments) {
  SplitSegments out;
  std::map<std::pair<double, double>, int> node_index;
  auto node_of = [&](const Point& p) {
    auto [it, inserted] = node_index.emplace(std::make_pair(p.x(), p.y()), out.nodes.size());
    if (inserted) out.nodes.push_back(p);
    return it->second;
  };
  const int num_segments = static_cast<int>(segments->size());
  out.pieces.resize(num_segments);
  for (int s = 0; s < num_segments; ++s) {
    RawSegment& seg = (*segments)[s];
    seg.splits.push_back({0.0, seg.a});
    seg.splits.push_back({1.0, seg.b});
    std::sort(seg.splits.begin(), seg.splits.end(),
              [](const auto& l, const auto& r) { return l.first < r.first; });
    int prev = node_of(seg.splits[0].second);
    for (size_t k = 1; k < seg.splits.size(); ++k) {
      const int node = node_of(seg.splits[k].second);
      if (node != prev) out.pieces[s].push_back({prev, node, s});
      prev = node;
    }
  }
  return out;
}

// Whether q lies inside the shape (inside an odd number of outlines).
bool InsideShape(const std::vector<Outline>& outlines, const Point& q) {
  bool in = false;
  for (const Outline& o : outlines) in ^= PolygonContains(o.points, q);
  return in;
}

// One cut or opening (`line`: its pieces in order; `first`: its first segment, for messages)
// clipped to the shape and appended as bi-directed edges: outside pieces at either end are
// dropped; an outside piece between inside ones, a line wholly outside, or a piece that another
// cut or opening already made an edge (`undirected`) is INVALID_ARGUMENT.
absl::Status ClipLine(const std::string& what, const RawSegment& first,
                      const std::vector<Piece>& line, const Points& nodes,
                      const std::vector<Outline>& outlines,
                      std::map<std::pair<int, int>, int>* undirected,
                      std::vector<GraphEdge>* edges) {
  std::vector<bool> in(line.size());
  for (size_t k = 0; k < line.size(); ++k) {
    in[k] = InsideShape(outlines, 0.5 * (nodes[line[k].from] + nodes[line[k].to]));
  }
  size_t begin = 0, end = line.size();
  while (begin < end && !in[begin]) ++begin;
  while (end > begin && !in[end - 1]) --end;
  if (begin == end) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ", ", Name(first), " lies outside the shape (near ", Where(first.a), ")"));
  }
  for (size_t k = begin; k < end; ++k) {
    if (!in[k]) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ", ", Name(first), " leaves the shape at ", Where(nodes[line[k].from]),
                       " and comes back; split it into separate cuts"));
    }
    auto key = std::minmax(line[k].from, line[k].to);
    if (undirected->count(key)) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": ", Name(first),
                                                     " overlaps another cut or opening at ",
                                                     Where(nodes[line[k].from])));
    }
    (*undirected)[key] = static_cast<int>(edges->size());
    edges->push_back({line[k].from, line[k].to, true});
  }
  return absl::OkStatus();
}

// The graph's edges: the outlines' pieces (1-directed), then each cut and opening clipped to the
// shape (ClipLine, bi-directed).
absl::StatusOr<std::vector<GraphEdge>> BuildEdges(const std::string& what,
                                                  const std::vector<RawSegment>& segments,
                                                  int num_outline_segments,
                                                  const SplitSegments& split,
                                                  const std::vector<Outline>& outlines) {
  std::vector<GraphEdge> edges;
  for (int s = 0; s < num_outline_segments; ++s) {
    for (const Piece& p : split.pieces[s]) edges.push_back({p.from, p.to, false});
  }
  const int num_segments = static_cast<int>(segments.size());
  std::map<std::pair<int, int>, int> undirected;  // for overlap detection of identical pieces
  for (int s = num_outline_segments; s < num_segments;) {
    int e = s;
    while (e < num_segments && segments[e].kind == segments[s].kind &&
           segments[e].element == segments[s].element) {
      ++e;
    }
    std::vector<Piece> line;
    for (int k = s; k < e; ++k) {
      line.insert(line.end(), split.pieces[k].begin(), split.pieces[k].end());
    }
    if (absl::Status status =
            ClipLine(what, segments[s], line, split.nodes, outlines, &undirected, &edges);
        !status.ok()) {
      return status;
    }
    s = e;
  }
  return edges;
}

// The flow's cycles as loops, outer (positive area) first, then holes, each in cycle order;
// every edge paired with its collocated twin on the other side of a cut or opening.
BoundaryGraph LoopsOfFlow(const GraphFlowResult& flow, const Points& nodes,
                          const std::vector<GraphEdge>& edges) {
  BoundaryGraph out;
  for (const GraphEdge& e : edges)
    ++(e.bidirected ? out.bi_directed_edges : out.one_directed_edges);
  std::vector<int> loop_order(flow.cycles.size());
  std::iota(loop_order.begin(), loop_order.end(), 0);
  std::vector<double> area(flow.cycles.size());
  for (size_t c = 0; c < flow.cycles.size(); ++c) {
    Points p;
    for (int n : flow.cycles[c].nodes) p.push_back(nodes[n]);
    area[c] = PolygonSignedArea(p);
  }
  std::stable_partition(loop_order.begin(), loop_order.end(), [&](int c) { return area[c] > 0; });
  std::vector<std::pair<int, int>> half_edge_place(2 * edges.size(), {-1, -1});
  for (size_t l = 0; l < loop_order.size(); ++l) {
    const FlowCycle& cycle = flow.cycles[loop_order[l]];
    BoundaryLoop loop;
    for (size_t k = 0; k < cycle.nodes.size(); ++k) {
      loop.points.push_back(nodes[cycle.nodes[k]]);
      half_edge_place[cycle.half_edges[k]] = {static_cast<int>(l), static_cast<int>(k)};
    }
    loop.outer = area[loop_order[l]] > 0;
    out.loops.push_back(std::move(loop));
  }
  for (size_t l = 0; l < loop_order.size(); ++l) {
    const FlowCycle& cycle = flow.cycles[loop_order[l]];
    for (int h : cycle.half_edges) {
      out.loops[l].twin.push_back(edges[h / 2].bidirected ? half_edge_place[h ^ 1]
                                                          : std::pair<int, int>{-1, -1});
    }
  }
  return out;
}

// The component of hole `hole`: the smallest outer loop around a point just on its drawing
// side, or -1.
int ComponentAround(const std::vector<BoundaryLoop>& loops, const BoundaryLoop& hole) {
  const Point a = hole.points[0], b = hole.points[1 % hole.points.size()];
  const Point d = b - a;
  const Point probe = 0.5 * (a + b) + 1e-7 * Point(-d.y(), d.x());
  int best = -1;
  double best_area = 0;
  for (const BoundaryLoop& outer : loops) {
    if (!outer.outer || !PolygonContains(outer.points, probe)) continue;
    const double a_outer = PolygonSignedArea(outer.points);
    if (best < 0 || a_outer < best_area) best = outer.component, best_area = a_outer;
  }
  return best;
}

// Components: one per outer loop, numbered in order; each hole joins ComponentAround's. Fills
// the equivalence class; INVALID_ARGUMENT for a hole inside no component.
absl::Status AssignComponents(const std::string& what, BoundaryGraph* out) {
  int components = 0;
  for (BoundaryLoop& loop : out->loops) {
    if (loop.outer) loop.component = components++;
  }
  out->equivalence.components = components;
  out->equivalence.holes_per_component.assign(components, 0);
  for (BoundaryLoop& loop : out->loops) {
    if (loop.outer) continue;
    const int best = ComponentAround(out->loops, loop);
    if (best < 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          what, ": the boundary through ", Where(loop.points[0]), " is not inside any component"));
    }
    loop.component = best;
    ++out->equivalence.holes;
    ++out->equivalence.holes_per_component[best];
  }
  std::sort(out->equivalence.holes_per_component.rbegin(),
            out->equivalence.holes_per_component.rend());
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<BoundaryGraph> BuildBoundaries(const Drawing& drawing, int drawing_number,
                                              const BoundaryOptions& options) {
  const std::string what = absl::StrCat("drawing ", drawing_number);
  if (drawing.outlines.empty()) return absl::InvalidArgumentError(what + " has no outline");
  absl::StatusOr<std::vector<Outline>> outlines = CleanOutlines(drawing, what);
  if (!outlines.ok()) return outlines.status();
  // Segments: the outlines', then the cuts' and openings'; split where they meet.
  std::vector<RawSegment> segments = OutlineSegments(*outlines);
  const int num_outline_segments = static_cast<int>(segments.size());
  if (absl::Status s = AddLineSegments(drawing, what, SnapDistance(*outlines, options), &segments);
      !s.ok()) {
    return s;
  }
  if (absl::Status s = SplitAtContacts(what, options, &segments); !s.ok()) return s;
  const SplitSegments split = SplitAtNodes(&segments);
  absl::StatusOr<std::vector<GraphEdge>> edges =
      BuildEdges(what, segments, num_outline_segments, split, *outlines);
  if (!edges.ok()) return edges.status();

  absl::StatusOr<GraphFlowResult> flow = DirectedGraphFlow(split.nodes, *edges);
  if (!flow.ok())
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", flow.status().message()));
  BoundaryGraph out = LoopsOfFlow(*flow, split.nodes, *edges);
  if (absl::Status s = AssignComponents(what, &out); !s.ok()) return s;
  return out;
}

}  // namespace inbetween::solver
