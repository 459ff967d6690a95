// Comesh outer loop: flips, collapses and splits applied to every shape at once, each accepted
// only if valid in every shape and not raising the comesh objective (see comesh_topology.h).
#include "solver/comesh/comesh_topology.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "solver/comesh/comesh_objective.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/validate.h"
#include "solver/mesh/vertex_star.h"

namespace inbetween::solver {
namespace {

bool LexicographicLess(const Point& p, const Point& q) {
  return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
}

// Edges (a, b), a < b, grouped by a in linear time: `for_each_edge(emit)` calls emit(a, b) for
// every edge (repeats allowed; it returns false when cancelled) and is called twice, to count and
// to fill (a counting sort on a). Then each bucket (a vertex's few higher neighbours, ascending)
// is sorted on its own and handed to bucket(a, begin, end). Polls `cancel` every 4096 buckets;
// false if it was set. One std::sort of all the pairs instead took 3.5% of the 35k-vertex S-Table
// 2 row, and ~0.1 s without a poll at 311k vertices.
template <typename ForEachEdge, typename Bucket>
bool ForEachBucket(int n, ForEachEdge&& for_each_edge, Bucket&& bucket, const CancelToken* cancel) {
  std::vector<int> start(n + 1, 0);
  if (!for_each_edge([&](int a, int) { ++start[a + 1]; })) return false;
  for (int a = 0; a < n; ++a) start[a + 1] += start[a];
  std::vector<int> higher(start[n]);
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    if (!for_each_edge([&](int a, int b) { higher[fill[a]++] = b; })) return false;
  }
  for (int a = 0; a < n; ++a) {
    if (a % 4096 == 0 && Cancelled(cancel)) return false;
    const auto begin = higher.begin() + start[a], end = higher.begin() + start[a + 1];
    std::sort(begin, end);
    bucket(a, begin, end);
  }
  return !Cancelled(cancel);
}

// Mutable triangle soup with vertex -> triangle incidence and the running objective sums.
class Editor {
 public:
  // With `cancel` set during construction (polled every 4096 triangles: the set-up takes ~0.2 s
  // at 311k vertices), stops early and cancelled() is true; the editor is then unusable.
  Editor(const Multimesh& mesh, const ComeshObjective& objective, const TopologyOptions& options,
         const std::vector<ShapeOutline>* outlines, const CancelToken* cancel)
      : objective_(objective),
        outlines_(outlines),
        options_(options),
        triangles_(mesh.triangles),
        alive_(mesh.triangles.size(), 1),
        shapes_(mesh.shapes),
        t0_(static_cast<double>(mesh.triangles.size())),
        t_(static_cast<int>(mesh.triangles.size())) {
    const int n = mesh.num_vertices();
    const int num_shapes = mesh.num_shapes();
    incident_.resize(n);
    removed_.assign(n, 0);
    locked_.assign(n, 0);
    protected_.assign(n, 0);
    std::vector<std::pair<std::pair<int, int>, int>> uses;
    if (!EdgeUses(triangles_, alive_, cancel, &uses)) {
      cancelled_ = true;
      return;
    }
    for (size_t t = 0; t < triangles_.size(); ++t) {
      if (t % 4096 == 0 && Cancelled(cancel)) {
        cancelled_ = true;
        return;
      }
      for (int k = 0; k < 3; ++k) incident_[triangles_[t][k]].push_back(static_cast<int>(t));
      double odt, mips;
      objective_.TriangleTerms(triangles_[t], shapes_, &odt, &mips);
      odt_sum_ += odt;
      mips_sum_ += mips;
    }
    boundary_nbrs_.assign(n, {-1, -1});
    many_boundary_edges_.assign(n, 0);
    fixed_.assign(n, 0);  // never slides: a non-manifold edge, cohesive, >2 boundary edges
    std::vector<char>& fixed = fixed_;
    for (const auto& [edge, count] : uses) {
      if (count != 2) protected_[edge.first] = protected_[edge.second] = 1;
      if (count > 2) fixed[edge.first] = fixed[edge.second] = 1;
      if (count != 1) continue;
      for (const auto& [v, u] : {edge, std::pair(edge.second, edge.first)}) {
        std::array<int, 2>& nb = boundary_nbrs_[v];
        if (nb[0] < 0) {
          nb[0] = u;
        } else if (nb[1] < 0) {
          nb[1] = u;
        } else {
          fixed[v] = 1;
          many_boundary_edges_[v] = 1;
        }
      }
    }
    for (int v : mesh.boundary) protected_[v] = 1;
    for (const auto& c : mesh.cohesive_edges) {
      for (int v : c) protected_[v] = fixed[v] = 1;
    }
    for (int v : mesh.pinned) protected_[v] = fixed[v] = 1;  // correspondence marks
    all_straight_ = num_shapes >= 64 ? ~uint64_t{0} : (uint64_t{1} << num_shapes) - 1;
    straight_.assign(n, 0);
    if (options.boundary_collapses && num_shapes <= 64) {
      for (int v = 0; v < n; ++v) {
        if (!fixed[v]) UpdateStraight(v);
      }
    }
    for (int s = 0; s < num_shapes; ++s) {
      double area = 0.0, length = 0.0;
      for (const Triangle& t : triangles_) area += 0.5 * SignedArea2(t, shapes_[s]);
      for (const auto& [edge, count] : uses) {
        length += (shapes_[s][edge.first] - shapes_[s][edge.second]).norm();
      }
      min_area2_.push_back(2.0 * options.min_area_ratio * area / t0_);
      mean_edge_.push_back(length / static_cast<double>(uses.size()));
    }
  }

  double Objective() const { return Objective(t_, odt_sum_, mips_sum_); }
  int num_triangles() const { return t_; }
  int corner_swaps() const { return corner_swaps_; }
  bool cancelled() const { return cancelled_; }

  // Interior edges (each once) as (a, b) with a < b, into *edges; false if `cancel` was set
  // (polled every 4096 items).
  bool InteriorEdges(const CancelToken* cancel, std::vector<std::pair<int, int>>* edges) const {
    std::vector<std::pair<std::pair<int, int>, int>> uses;
    if (!EdgeUses(triangles_, alive_, cancel, &uses)) return false;
    edges->clear();
    for (const auto& [edge, count] : uses) {
      if (count == 2) edges->push_back(edge);
    }
    return true;
  }

  // The vertices marked since the last call (ascending), and clears the marks.
  std::vector<int> TakeDirty() {
    std::vector<int> out;
    out.swap(dirty_list_);
    for (int v : out) dirty_[v] = 0;
    std::sort(out.begin(), out.end());
    return out;
  }

  // The interior edges (a, b), a < b, with an endpoint in `vertices`, ascending (each once),
  // into *interior; false if `cancel` was set (polled every 4096 vertices and edges).
  bool InteriorEdgesAt(const std::vector<int>& vertices, const CancelToken* cancel,
                       std::vector<std::pair<int, int>>* interior) const {
    // Ascending (a, b), each once: a bucket's repeats skipped.
    const int n = static_cast<int>(incident_.size());
    auto for_each_edge = [&](auto&& emit) {
      for (size_t i = 0; i < vertices.size(); ++i) {
        if (i % 4096 == 0 && Cancelled(cancel)) return false;
        const int v = vertices[i];
        if (v >= n) continue;
        for (int t : incident_[v]) {
          for (int u : triangles_[t]) {
            if (u != v) emit(std::min(u, v), std::max(u, v));
          }
        }
      }
      return true;
    };
    interior->clear();
    int t1 = -1, t2 = -1;
    return ForEachBucket(
        n, for_each_edge,
        [&](int a, auto begin, auto end) {
          for (auto i = begin; i != end; ++i) {
            if (i != begin && *i == *(i - 1)) continue;
            if (EdgeTriangles(a, *i, &t1, &t2)) interior->push_back({a, *i});
          }
        },
        cancel);
  }

  // Boundary collapse candidates: the boundary edges (a, b), a < b, with an endpoint that may be
  // removed (straight in every shape), each once, ascending; with corner swaps, also those whose
  // two endpoints are each straight where the other is a corner (MergeableAlong).
  std::vector<std::pair<int, int>> BoundaryCollapseEdges() const {
    std::vector<std::pair<int, int>> edges;
    for (size_t v = 0; v < straight_.size(); ++v) {
      if (straight_[v] == 0 || removed_[v]) continue;
      for (int u : boundary_nbrs_[v]) {
        if (straight_[v] == all_straight_ || MergeableAlong(static_cast<int>(v), u) ||
            MergeableAlong(u, static_cast<int>(v))) {
          edges.push_back(std::minmax(static_cast<int>(v), u));
        }
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    return edges;
  }
  // True if a or b is straight in every shape (a plain boundary collapse, not a corner swap).
  bool Removable(int a, int b) const {
    return straight_[a] == all_straight_ || straight_[b] == all_straight_;
  }
  // True if b may merge into its boundary neighbour a: b is not fixed and lies strictly inside
  // the straight segment of its own two boundary neighbours in every shape or (with corner
  // swaps) in every shape where a does not.
  bool MergeableAlong(int a, int b) const {
    return a >= 0 && b >= 0 && !fixed_[b] && straight_[b] != 0 &&
           (boundary_nbrs_[b][0] == a || boundary_nbrs_[b][1] == a) &&
           (straight_[b] == all_straight_ ||
            (options_.corner_swaps && (straight_[a] | straight_[b]) == all_straight_));
  }

  // True if b (not fixed) is a boundary neighbour of a and, in every shape where b is not
  // straight, lies within kCoincident mean edge lengths of a: merging them moves a corner by at
  // most that much (sliver removal only).
  bool CoincidentAlong(int a, int b) const {
    constexpr double kCoincident = 1e-2;
    if (a < 0 || b < 0 || fixed_[b]) return false;
    if (boundary_nbrs_[b][0] != a && boundary_nbrs_[b][1] != a) return false;
    for (size_t s = 0; s < shapes_.size(); ++s) {
      if (straight_[b] >> s & 1) continue;
      if ((shapes_[s][a] - shapes_[s][b]).norm() > kCoincident * mean_edge_[s]) return false;
    }
    return true;
  }

  // Per shape, sorted (LexicographicLess): places a coincident merge keeps (RemoveSlivers).
  void set_anchors(const std::vector<Points>* anchors) { anchors_ = anchors; }
  // True if v's place in shape s is one of the anchors.
  bool Anchor(size_t s, int v) const {
    if (anchors_ == nullptr) return false;
    const Points& a = (*anchors_)[s];
    return std::binary_search(a.begin(), a.end(), shapes_[s][v], LexicographicLess);
  }

  // Twice the area the boundary polygon of shape s changes by when boundary vertex v leaves it.
  double DropArea2(size_t s, int v) const {
    const Points& x = shapes_[s];
    return std::abs(SignedArea2(x[boundary_nbrs_[v][0]], x[v], x[boundary_nbrs_[v][1]]));
  }

  // Length of edge (a, b) relative to the mean edge length, max (or min) over shapes.
  double RelativeLength(int a, int b, bool max) const {
    double r = max ? 0.0 : std::numeric_limits<double>::infinity();
    for (size_t s = 0; s < shapes_.size(); ++s) {
      const double l = (shapes_[s][a] - shapes_[s][b]).norm() / mean_edge_[s];
      r = max ? std::max(r, l) : std::min(r, l);
    }
    return r;
  }

  // The two live triangles sharing edge (a, b), or false.
  bool EdgeTriangles(int a, int b, int* t1, int* t2) const {
    return EdgeTriangleCount(a, b, t1, t2) == 2;
  }
  // The number of live triangles on edge (a, b); the first two into *t1, *t2.
  int EdgeTriangleCount(int a, int b, int* t1, int* t2) const {
    int found = 0;
    for (int t : incident_[a]) {
      const Triangle& tri = triangles_[t];
      if (tri[0] == b || tri[1] == b || tri[2] == b) {
        if (found == 0) *t1 = t;
        if (found == 1) *t2 = t;
        ++found;
      }
    }
    return found;
  }

  // With by_quality (sliver removal) the flip must raise the worst quality of the two
  // triangles instead of lowering the objective.
  bool TryFlip(int a, int b, bool by_quality = false) {
    int t1 = -1, t2 = -1;
    if (!EdgeTriangles(a, b, &t1, &t2)) return false;
    // Orient: t1 = (a, b, c) and t2 = (b, a, d) up to rotation.
    if (Opposite(triangles_[t1], a, b) < 0) std::swap(t1, t2);
    const int cc = Opposite(triangles_[t1], a, b);
    const int dd = Opposite(triangles_[t2], b, a);
    if (cc < 0 || dd < 0 || cc == dd || Adjacent(cc, dd)) return false;
    const Triangle n1 = {a, dd, cc}, n2 = {dd, b, cc};
    if (!Positive(n1) || !Positive(n2)) return false;
    double odt_old, mips_old, odt_new, mips_new;
    Terms({triangles_[t1], triangles_[t2]}, &odt_old, &mips_old);
    Terms({n1, n2}, &odt_new, &mips_new);
    const double before = Objective();
    const double after =
        Objective(t_, odt_sum_ - odt_old + odt_new, mips_sum_ - mips_old + mips_new);
    if (by_quality ? !(WorstQuality({n1, n2}) > WorstQuality({triangles_[t1], triangles_[t2]}))
                   : !(after < before - 1e-12 * std::abs(before))) {
      return false;
    }
    Replace(t1, n1);
    Replace(t2, n2);
    odt_sum_ += odt_new - odt_old;
    mips_sum_ += mips_new - mips_old;
    return true;
  }

  // Removes b by merging it into a: b interior (edge ab interior), or ab a boundary edge with
  // MergeableAlong(a, b). Along the boundary the merged vertex takes, in each shape, a's place
  // where b is straight there and b's place where b is a corner (a is straight there then): the
  // boundary polyline of every shape is unchanged as a point set, since the vertex dropped from
  // it lay on the straight segment of its neighbours. A corner of one shape can so move past a
  // corner of another along the boundary (square -> hexagon: a square corner onto a hexagon
  // corner), which sliding alone never does: the optimizer's sliders stop at corners.
  //
  // With by_quality (sliver removal) the place is the one with the better worst quality of the
  // new triangles, and the collapse must raise the worst quality of the triangles it changes
  // instead of not raising the objective.
  //
  // Also with by_quality, b may merge into a boundary neighbour a it (nearly) coincides with in
  // every shape where b is not straight (CoincidentAlong): a slider that slid onto its neighbour.
  bool TryCollapse(int a, int b, bool by_quality = false) {
    if (removed_[a] || removed_[b] || locked_[a] || locked_[b]) return false;
    Collapse c;
    c.coincident = by_quality && !MergeableAlong(a, b) && CoincidentAlong(a, b);
    c.along_boundary = c.coincident || MergeableAlong(a, b);
    if (protected_[b] && !c.along_boundary) return false;
    if (!CollapseLinks(a, b, &c)) return false;
    double odt_old, mips_old;
    Terms(c.old_tris, &odt_old, &mips_old);
    const double before = Objective();
    const int num_shapes = static_cast<int>(shapes_.size());
    std::vector<Point> original(num_shapes);
    for (int s = 0; s < num_shapes; ++s) original[s] = shapes_[s][a];
    const std::vector<Point> saved = MergedPlaces(a, b, c);
    // Minimized: the objective, or (by_quality) minus the worst quality. Candidate places for
    // the merged vertex: `saved`, or (a free) its midpoint with b, in every shape.
    double best = std::numeric_limits<double>::infinity();
    int best_place = -1;
    double best_odt = 0.0, best_mips = 0.0;
    for (int place = 0; place < (protected_[a] ? 1 : 2); ++place) {
      for (int s = 0; s < num_shapes; ++s) {
        shapes_[s][a] = place == 0 ? saved[s] : Point(0.5 * (saved[s] + shapes_[s][b]));
      }
      bool ok = true;
      for (const Triangle& tri : c.new_tris) ok = ok && Positive(tri);
      if (ok) {
        double odt_new, mips_new;
        Terms(c.new_tris, &odt_new, &mips_new);
        const double after = by_quality ? -WorstQuality(c.new_tris)
                                        : Objective(t_ - c.on_edge, odt_sum_ - odt_old + odt_new,
                                                    mips_sum_ - mips_old + mips_new);
        if (after < best) {
          best = after;
          best_place = place;
          best_odt = odt_new - odt_old;
          best_mips = mips_new - mips_old;
        }
      }
    }
    for (int s = 0; s < num_shapes; ++s) {
      shapes_[s][a] = best_place == 1 ? Point(0.5 * (saved[s] + shapes_[s][b])) : saved[s];
    }
    const double limit = by_quality ? -WorstQuality(c.old_tris) : before;
    if (best_place < 0 || (by_quality ? !(best < limit) : !(best <= limit))) {
      for (int s = 0; s < num_shapes; ++s) shapes_[s][a] = original[s];
      return false;
    }
    ApplyCollapse(a, b, c);
    odt_sum_ += best_odt;
    mips_sum_ += best_mips;
    return true;
  }

  // What a collapse of b into a changes, once its links allow it.
  struct Collapse {
    bool coincident = false;            // b slid onto its boundary neighbour a (CoincidentAlong)
    bool along_boundary = false;        // ab is a boundary edge (or coincident)
    int on_edge = 0, t1 = -1, t2 = -1;  // the triangles on edge ab (1 along the boundary)
    std::vector<int> na, nb;            // the neighbours of a and b
    std::vector<Triangle> old_tris, new_tris;  // the one-rings before and after
  };

  // Whether b may merge into a by the edge and link conditions (the common neighbours of a and b
  // are exactly the opposite vertices); fills c's triangles and neighbours.
  bool CollapseLinks(int a, int b, Collapse* c) const {
    c->on_edge = EdgeTriangleCount(a, b, &c->t1, &c->t2);
    if (c->on_edge != (c->along_boundary ? 1 : 2)) return false;
    c->na = Neighbours(a);
    c->nb = Neighbours(b);
    std::vector<int> common;
    std::set_intersection(c->na.begin(), c->na.end(), c->nb.begin(), c->nb.end(),
                          std::back_inserter(common));
    if (static_cast<int>(common.size()) != c->on_edge) return false;
    // Affected triangles: the one-rings of a and b (those on edge ab disappear).
    std::vector<int> affected = incident_[a];
    for (int t : incident_[b]) {
      if (t != c->t1 && t != c->t2) affected.push_back(t);
    }
    for (int t : affected) {
      c->old_tris.push_back(triangles_[t]);
      if (t == c->t1 || t == c->t2) continue;
      Triangle tri = triangles_[t];
      for (int k = 0; k < 3; ++k) {
        if (tri[k] == b) tri[k] = a;
      }
      c->new_tris.push_back(tri);
    }
    return true;
  }

  // The merged vertex's place in each shape before the midpoint is tried: a's own, except along
  // the boundary where b is a corner, which keeps b's place. A coincident pair keeps a fixed a's
  // place, else the place that is an anchor (an input boundary point: a corner that never
  // moved, not the slider that slid onto it), else the place of the one whose removal changes
  // the shape's boundary polygon more.
  std::vector<Point> MergedPlaces(int a, int b, const Collapse& c) const {
    const int num_shapes = static_cast<int>(shapes_.size());
    std::vector<Point> saved(num_shapes);
    for (int s = 0; s < num_shapes; ++s) {
      saved[s] = shapes_[s][a];
      if (c.along_boundary && !(straight_[b] >> s & 1)) {
        bool keep_b = true;
        if (c.coincident) {
          const bool anchor_a = Anchor(s, a), anchor_b = Anchor(s, b);
          keep_b =
              !fixed_[a] && (anchor_a != anchor_b ? anchor_b : DropArea2(s, a) < DropArea2(s, b));
        }
        if (keep_b) saved[s] = shapes_[s][b];
      }
    }
    return saved;
  }

  // Removes b (a at its chosen place): the triangles on ab die, b's others take a, the boundary
  // neighbours and straightness follow, and a, b and their neighbours are locked for the pass.
  void ApplyCollapse(int a, int b, const Collapse& c) {
    Kill(c.t1);
    if (c.on_edge == 2) Kill(c.t2);
    const std::vector<int> moved = incident_[b];
    for (int t : moved) {
      Triangle tri = triangles_[t];
      for (int k = 0; k < 3; ++k) {
        if (tri[k] == b) tri[k] = a;
      }
      Replace(t, tri);
    }
    for (int t : incident_[a]) {  // a may have moved: every triangle around it changed
      for (int v : triangles_[t]) MarkDirty(v);
    }
    removed_[b] = 1;
    t_ -= c.on_edge;
    corner_swaps_ += c.along_boundary && !c.coincident && straight_[b] != all_straight_;
    if (c.along_boundary) {  // a and b's other boundary neighbour n become neighbours
      const int n = boundary_nbrs_[b][0] == a ? boundary_nbrs_[b][1] : boundary_nbrs_[b][0];
      for (auto [v, old_nbr, new_nbr] : {std::tuple(a, b, n), std::tuple(n, b, a)}) {
        std::array<int, 2>& nbrs = boundary_nbrs_[v];
        (nbrs[0] == old_nbr ? nbrs[0] : nbrs[1]) = new_nbr;
        // As b lay on the straight line of its neighbours (or a took its place), only a
        // vertex straight everywhere can change (the tolerance of StrictlyInsideSegment grows
        // with the segment); a corner swap makes a a corner where b was one.
        if (straight_[v] == all_straight_) UpdateStraight(v);
      }
      straight_[a] &= straight_[b];
      straight_[b] = 0;
    }
    locked_[a] = locked_[b] = 1;
    for (int v : c.na) locked_[v] = 1;
    for (int v : c.nb) locked_[v] = 1;
  }

  // Inserts a new vertex at the midpoint of edge (a, b) in every shape: an interior edge, or a
  // boundary edge between two vertices that are not fixed (not cohesive, not a mark); with the
  // optimizer's outlines a boundary edge's new vertex is on the outline instead
  // (ShapeOutline::SplitPoint: the midpoint on a straight stretch, the arc's middle otherwise).
  bool TrySplit(int a, int b) {
    if (locked_[a] || locked_[b]) return false;
    int t1 = -1, t2 = -1;
    const int on_edge = EdgeTriangleCount(a, b, &t1, &t2);
    const bool boundary = on_edge == 1;
    if (boundary) {
      const bool neighbours = boundary_nbrs_[a][0] == b || boundary_nbrs_[a][1] == b;
      if (!options_.boundary_splits || fixed_[a] || fixed_[b] || !neighbours) return false;
    } else if (on_edge != 2) {
      return false;
    }
    const int m = static_cast<int>(removed_.size());
    std::vector<Point> at;  // the new vertex in each shape
    for (size_t s = 0; s < shapes_.size(); ++s) {
      const Points& x = shapes_[s];
      std::optional<Point> p = 0.5 * (x[a] + x[b]);
      if (boundary && outlines_ != nullptr) {
        const ShapeOutline& outline = (*outlines_)[s];
        p = outline.SplitPoint(x[a], x[b], outline.tolerance());
        if (!p) return false;
      }
      at.push_back(*p);
    }
    for (size_t s = 0; s < shapes_.size(); ++s) shapes_[s].push_back(at[s]);
    std::vector<Triangle> new_tris;
    std::vector<int> split = {t1};
    if (!boundary) split.push_back(t2);
    std::vector<Triangle> old_tris;
    for (int t : split) old_tris.push_back(triangles_[t]);
    for (int t : split) {
      const Triangle& tri = triangles_[t];
      for (int end : {a, b}) {
        Triangle half = tri;
        for (int k = 0; k < 3; ++k) {
          if (half[k] == (end == a ? b : a)) half[k] = m;
        }
        new_tris.push_back(half);
      }
    }
    bool ok = true;
    for (const Triangle& tri : new_tris) ok = ok && Positive(tri);
    double odt_old, mips_old, odt_new = 0.0, mips_new = 0.0;
    Terms(old_tris, &odt_old, &mips_old);
    if (ok) Terms(new_tris, &odt_new, &mips_new);
    const double before = Objective();
    const double after =
        Objective(t_ + on_edge, odt_sum_ - odt_old + odt_new, mips_sum_ - mips_old + mips_new);
    if (!ok || !(after < before - 1e-12 * std::abs(before))) {
      for (Points& x : shapes_) x.pop_back();
      return false;
    }
    // Every per-vertex array grows by m.
    removed_.push_back(0);
    protected_.push_back(boundary ? 1 : 0);
    locked_.push_back(1);
    many_boundary_edges_.push_back(0);
    incident_.emplace_back();
    fixed_.push_back(0);
    boundary_nbrs_.push_back(boundary ? std::array<int, 2>{a, b} : std::array<int, 2>{-1, -1});
    straight_.push_back(0);
    if (boundary) {
      for (auto [v, other] : {std::pair(a, b), std::pair(b, a)}) {
        std::array<int, 2>& nbrs = boundary_nbrs_[v];
        (nbrs[0] == other ? nbrs[0] : nbrs[1]) = m;
      }
      if (options_.boundary_collapses && shapes_.size() <= 64) UpdateStraight(m);
      boundary_splits_.push_back({a, b, m});
    }
    Replace(t1, new_tris[0]);
    Add(new_tris[1]);
    if (!boundary) {
      Replace(t2, new_tris[2]);
      Add(new_tris[3]);
    }
    t_ += on_edge;
    odt_sum_ += odt_new - odt_old;
    mips_sum_ += mips_new - mips_old;
    locked_[a] = locked_[b] = 1;
    return true;
  }

  // Sliver removal: triangle t = (a, b, c) on boundary edge (a, b), c an interior vertex lying
  // almost on that edge in every shape. c moves onto the edge (its projection, strictly inside
  // the segment) in every shape and joins the boundary between a and b; t disappears. Every
  // shape's domain stays the same point set (c lies on the polygon's edge); with the optimizer's
  // outlines the projection must also lie on the shape's outline (ShapeOutline::Locate), so
  // every boundary vertex stays on it. Accepted if c's other triangles stay positive
  // (min_area_ratio) and their worst quality beats t's.
  bool TrySnap(int a, int b, int c) {
    if (removed_[c] || locked_[a] || locked_[b] || locked_[c] || protected_[c]) return false;
    if (boundary_nbrs_[c][0] >= 0) return false;  // c on a boundary already
    int t1 = -1, t2 = -1;
    if (EdgeTriangleCount(a, b, &t1, &t2) != 1) return false;
    if (boundary_nbrs_[a][0] != b && boundary_nbrs_[a][1] != b) return false;
    const Triangle sliver = triangles_[t1];
    if (sliver[0] != c && sliver[1] != c && sliver[2] != c) return false;
    const int num_shapes = static_cast<int>(shapes_.size());
    std::vector<Point> original(num_shapes);
    for (int s = 0; s < num_shapes; ++s) {
      const Point& pa = shapes_[s][a];
      const Point ab = shapes_[s][b] - pa;
      const double lambda = (shapes_[s][c] - pa).dot(ab) / ab.squaredNorm();
      if (!(lambda > 0.05 && lambda < 0.95)) return false;
      if (outlines_ != nullptr) {
        const ShapeOutline& outline = (*outlines_)[s];
        if (!outline.Locate(pa + lambda * ab, outline.tolerance())) return false;
      }
      original[s] = shapes_[s][c];
    }
    std::vector<Triangle> others;
    for (int t : incident_[c]) {
      if (t != t1) others.push_back(triangles_[t]);
    }
    std::vector<Triangle> old_tris = others;
    old_tris.push_back(sliver);
    const double old_worst = WorstQuality(old_tris);
    double odt_old, mips_old;
    Terms(old_tris, &odt_old, &mips_old);
    for (int s = 0; s < num_shapes; ++s) {
      const Point& pa = shapes_[s][a];
      const Point ab = shapes_[s][b] - pa;
      shapes_[s][c] = pa + (shapes_[s][c] - pa).dot(ab) / ab.squaredNorm() * ab;
    }
    bool ok = true;
    for (const Triangle& tri : others) ok = ok && Positive(tri);
    if (!ok || !(WorstQuality(others) > old_worst)) {
      for (int s = 0; s < num_shapes; ++s) shapes_[s][c] = original[s];
      return false;
    }
    double odt_new, mips_new;
    Terms(others, &odt_new, &mips_new);
    Kill(t1);
    for (int t : incident_[c]) {
      for (int v : triangles_[t]) MarkDirty(v);
    }
    --t_;
    odt_sum_ += odt_new - odt_old;
    mips_sum_ += mips_new - mips_old;
    boundary_nbrs_[c] = {a, b};
    for (auto [v, other] : {std::pair(a, b), std::pair(b, a)}) {
      std::array<int, 2>& nbrs = boundary_nbrs_[v];
      (nbrs[0] == other ? nbrs[0] : nbrs[1]) = c;
    }
    protected_[c] = 1;
    if (options_.boundary_collapses && shapes_.size() <= 64) UpdateStraight(c);
    boundary_splits_.push_back({a, b, c});
    locked_[a] = locked_[b] = locked_[c] = 1;
    ++snaps_;
    return true;
  }

  // One attempt on a sliver, triangle t: a needle (one edge much shorter than the longest, in the
  // shape where t is worst) collapses that edge; a cap (a corner near the opposite, longest edge)
  // flips that edge if it is interior or snaps the corner onto it if it is on the boundary; then
  // collapses of the corner into either end of the longest edge. All judged by quality.
  bool TryRemoveSliver(int t) {
    if (!alive_[t]) return false;
    const Triangle tri = triangles_[t];
    int worst_shape = 0;
    double worst = std::numeric_limits<double>::infinity();
    for (size_t s = 0; s < shapes_.size(); ++s) {
      const double q = Quality(s, tri);
      if (q < worst) worst = q, worst_shape = static_cast<int>(s);
    }
    const Points& x = shapes_[worst_shape];
    // Edge k is opposite corner k.
    std::array<double, 3> length;
    for (int k = 0; k < 3; ++k) length[k] = (x[tri[(k + 1) % 3]] - x[tri[(k + 2) % 3]]).norm();
    const int longest =
        static_cast<int>(std::max_element(length.begin(), length.end()) - length.begin());
    const int shortest =
        static_cast<int>(std::min_element(length.begin(), length.end()) - length.begin());
    const int c = tri[longest], a = tri[(longest + 1) % 3], b = tri[(longest + 2) % 3];
    if (length[shortest] < 0.2 * length[longest]) {
      const int p = tri[(shortest + 1) % 3], q = tri[(shortest + 2) % 3];
      if (TryCollapse(p, q, true) || TryCollapse(q, p, true)) return true;
    }
    int t1 = -1, t2 = -1;
    const int on_edge = EdgeTriangleCount(a, b, &t1, &t2);
    if (on_edge == 2 && !locked_[a] && !locked_[b] && !locked_[c] && TryFlip(a, b, true)) {
      locked_[a] = locked_[b] = locked_[c] = 1;
      return true;
    }
    if (on_edge == 1 && TrySnap(a, b, c)) return true;
    return TryCollapse(a, c, true) || TryCollapse(b, c, true);
  }

  // Live triangles whose quality is below min_quality in some shape, worst first.
  std::vector<int> Slivers(double min_quality) const {
    std::vector<std::pair<double, int>> found;
    for (size_t t = 0; t < triangles_.size(); ++t) {
      if (!alive_[t]) continue;
      const double q = WorstQuality({triangles_[t]});
      if (q < min_quality) found.push_back({q, static_cast<int>(t)});
    }
    std::sort(found.begin(), found.end());
    std::vector<int> out;
    for (const auto& [q, t] : found) out.push_back(t);
    return out;
  }
  // Between sliver sweeps: a later sweep may work where an earlier one did (Compact traces the
  // boundary loops as they now run, whatever sequence of boundary operations made them).
  void Unlock() { std::fill(locked_.begin(), locked_.end(), 0); }
  int snaps() const { return snaps_; }

  // Boundary edges (a, b), a < b, whose endpoints are not fixed, each once, ascending.
  std::vector<std::pair<int, int>> SplittableBoundaryEdges() const {
    std::vector<std::pair<int, int>> edges;
    for (size_t v = 0; v < boundary_nbrs_.size(); ++v) {
      if (removed_[v] || fixed_[v]) continue;
      for (int u : boundary_nbrs_[v]) {
        if (u > static_cast<int>(v) && !fixed_[u]) edges.push_back({static_cast<int>(v), u});
      }
    }
    std::sort(edges.begin(), edges.end());
    return edges;
  }

  // The boundary loop through the first kept vertex of `loop` (an input loop, interior on the
  // left), walked along boundary_nbrs_ in the direction of its live triangles, in editor
  // numbering. Empty if that walk is not safe: a vertex with more than two boundary edges on the
  // way, a step that is not a boundary edge, a kept vertex of `loop` the walk does not meet (a
  // listed vertex inside the mesh), or no way back to the start.
  std::vector<int> Traced(const std::vector<int>& loop) const {
    int start = -1;
    for (int v : loop) {
      if (!removed_[v]) {
        start = v;
        break;
      }
    }
    if (start < 0 || many_boundary_edges_[start]) return {};
    auto directed = [&](int u, int w) {  // a live triangle runs u -> w
      for (int t : incident_[u]) {
        if (Opposite(triangles_[t], u, w) >= 0) return true;
      }
      return false;
    };
    std::vector<int> out;
    int prev = -1, cur = start;
    const size_t limit = removed_.size();
    do {
      if (many_boundary_edges_[cur] || out.size() > limit) return {};
      out.push_back(cur);
      const auto [n0, n1] = boundary_nbrs_[cur];
      if (n0 < 0 || n1 < 0) return {};
      const int next = prev < 0 ? (directed(cur, n0) ? n0 : n1) : (n0 == prev ? n1 : n0);
      int t1 = -1, t2 = -1;
      if (removed_[next] || EdgeTriangleCount(cur, next, &t1, &t2) != 1 || !directed(cur, next)) {
        return {};
      }
      prev = cur;
      cur = next;
    } while (cur != start);
    std::vector<int> sorted = out;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return {};
    for (int v : loop) {
      if (!removed_[v] && !std::binary_search(sorted.begin(), sorted.end(), v)) return {};
    }
    return out;
  }

  Multimesh Compact(const Multimesh& input) const {
    const int n = static_cast<int>(removed_.size());
    std::vector<int> index(n, -1);
    int next = 0;
    for (int v = 0; v < n; ++v) {
      if (!removed_[v]) index[v] = next++;
    }
    Multimesh out;
    for (size_t t = 0; t < triangles_.size(); ++t) {
      if (!alive_[t]) continue;
      const Triangle& tri = triangles_[t];
      out.triangles.push_back({index[tri[0]], index[tri[1]], index[tri[2]]});
    }
    for (const Points& x : shapes_) {
      Points y;
      y.reserve(next);
      for (int v = 0; v < n; ++v) {
        if (!removed_[v]) y.push_back(x[v]);
      }
      out.shapes.push_back(std::move(y));
    }
    // Boundary collapses remove vertices from the boundary lists; cohesive vertices are never
    // removed, so the cohesive edges (and the indices into them) keep their order.
    auto kept = [&](const std::vector<int>& list) {
      std::vector<int> out_list;
      for (int v : list) {
        if (!removed_[v]) out_list.push_back(index[v]);
      }
      return out_list;
    };
    // Boundary splits insert their vertex between the edge's two ends (next to each other in
    // the kept list, cyclically).
    std::map<std::pair<int, int>, int> inserted;
    for (const auto& [a, b, m] : boundary_splits_) {
      inserted[std::minmax(index[a], index[b])] = index[m];
    }
    auto with_splits = [&](const std::vector<int>& loop) {
      if (inserted.empty()) return loop;
      std::vector<int> out_loop;
      for (size_t i = 0; i < loop.size(); ++i) {
        out_loop.push_back(loop[i]);
        const auto it = inserted.find(std::minmax(loop[i], loop[(i + 1) % loop.size()]));
        if (it != inserted.end()) out_loop.push_back(it->second);
      }
      return out_loop;
    };
    // Preferably the loop as the boundary now runs (boundary_nbrs_), which follows any sequence
    // of boundary operations; the patched input list where it cannot be traced.
    auto loop_of = [&](const std::vector<int>& loop) {
      std::vector<int> out_loop = Traced(loop);
      if (out_loop.empty()) return with_splits(kept(loop));
      for (int& v : out_loop) v = index[v];
      return out_loop;
    };
    for (const std::vector<int>& loop : input.boundary_loops) {
      out.boundary_loops.push_back(loop_of(loop));
    }
    if (input.boundary_loops.empty()) {
      out.boundary = loop_of(input.boundary);
    } else {
      for (const std::vector<int>& loop : out.boundary_loops) {
        out.boundary.insert(out.boundary.end(), loop.begin(), loop.end());
      }
    }
    for (const auto& c : input.cohesive_edges) {
      out.cohesive_edges.push_back({index[c[0]], index[c[1]], index[c[2]], index[c[3]]});
    }
    out.cohesive_closed = input.cohesive_closed;
    out.pinned = kept(input.pinned);  // never removed (fixed), still ascending
    return out;
  }

 private:
  // Bit s of straight_[v]: v has two boundary neighbours and lies strictly inside the straight
  // segment between them in shape s (where the optimizer lets it slide), so removing it from that
  // shape's boundary polyline keeps the shape's domain.
  void UpdateStraight(int v) {
    const auto [p, q] = boundary_nbrs_[v];
    uint64_t bits = 0;
    for (size_t s = 0; p >= 0 && q >= 0 && s < shapes_.size(); ++s) {
      if (StrictlyInsideSegment(shapes_[s][p], shapes_[s][q], shapes_[s][v])) {
        bits |= uint64_t{1} << s;
      }
    }
    straight_[v] = bits;
  }

  double Objective(int t, double odt, double mips) const {
    const double w = objective_.map_weight();
    return (1.0 - w) * (t / t0_) * odt + w * mips;
  }

  void Terms(const std::vector<Triangle>& tris, double* odt, double* mips) const {
    *odt = *mips = 0.0;
    for (const Triangle& t : tris) {
      double o, m;
      objective_.TriangleTerms(t, shapes_, &o, &m);
      *odt += o;
      *mips += m;
    }
  }

  double Quality(size_t s, const Triangle& t) const {
    const Points& x = shapes_[s];
    return TriangleQuality(x[t[0]], x[t[1]], x[t[2]]);
  }
  double WorstQuality(const std::vector<Triangle>& tris) const {
    double q = std::numeric_limits<double>::infinity();
    for (const Triangle& t : tris) {
      for (size_t s = 0; s < shapes_.size(); ++s) q = std::min(q, Quality(s, t));
    }
    return q;
  }

  bool Positive(const Triangle& t) const {
    for (size_t s = 0; s < shapes_.size(); ++s) {
      const Points& x = shapes_[s];
      if (!(SignedArea2(t, x) > min_area2_[s])) return false;
    }
    return true;
  }

  // The third vertex of `tri` if it contains the directed edge a -> b, else -1.
  static int Opposite(const Triangle& tri, int a, int b) {
    for (int k = 0; k < 3; ++k) {
      if (tri[k] == a && tri[(k + 1) % 3] == b) return tri[(k + 2) % 3];
    }
    return -1;
  }

  bool Adjacent(int a, int b) const {
    for (int t : incident_[a]) {
      const Triangle& tri = triangles_[t];
      if (tri[0] == b || tri[1] == b || tri[2] == b) return true;
    }
    return false;
  }

  std::vector<int> Neighbours(int v) const { return StarNeighbours(triangles_, incident_[v], v); }

  void MarkDirty(int v) {
    if (v >= static_cast<int>(dirty_.size())) dirty_.resize(v + 1, 0);
    if (!dirty_[v]) {
      dirty_[v] = 1;
      dirty_list_.push_back(v);
    }
  }
  void Detach(int t) {
    for (int v : triangles_[t]) {
      MarkDirty(v);
      auto& list = incident_[v];
      list.erase(std::find(list.begin(), list.end(), t));
    }
  }
  void Attach(int t) {
    for (int v : triangles_[t]) {
      MarkDirty(v);
      incident_[v].push_back(t);
    }
  }
  void Replace(int t, const Triangle& tri) {
    Detach(t);
    triangles_[t] = tri;
    Attach(t);
  }
  void Kill(int t) {
    Detach(t);
    alive_[t] = 0;
  }
  void Add(const Triangle& tri) {
    triangles_.push_back(tri);
    alive_.push_back(1);
    Attach(static_cast<int>(triangles_.size()) - 1);
  }

  const ComeshObjective& objective_;
  const std::vector<ShapeOutline>* outlines_ = nullptr;  // may be null
  const std::vector<Points>* anchors_ = nullptr;         // RemoveSlivers' anchors; may be null
  const TopologyOptions& options_;
  std::vector<Triangle> triangles_;
  std::vector<char> alive_;
  std::vector<Points> shapes_;
  std::vector<std::vector<int>> incident_;
  std::vector<char> removed_, locked_, protected_;
  std::vector<char> many_boundary_edges_;          // more than two boundary edges (Traced)
  std::vector<std::array<int, 2>> boundary_nbrs_;  // the two boundary neighbours, or -1
  // Never removed along the boundary, and no boundary edge at it is split: non-manifold,
  // cohesive-edge and mark vertices, and those with more than two boundary edges (constructor).
  std::vector<char> fixed_;
  std::vector<uint64_t> straight_;  // per vertex, the shapes where it is a slider (UpdateStraight)
  uint64_t all_straight_ = 0;       // every shape's bit
  int corner_swaps_ = 0;
  int snaps_ = 0;
  // (a, b, m): m split boundary edge (a, b), a new vertex or (TrySnap) an interior one.
  std::vector<std::array<int, 3>> boundary_splits_;
  std::vector<double> min_area2_, mean_edge_;
  double t0_;
  int t_;
  double odt_sum_ = 0.0, mips_sum_ = 0.0;
  bool cancelled_ = false;
  // Vertices whose triangles changed (or moved) since the last TakeDirty().
  std::vector<char> dirty_;
  std::vector<int> dirty_list_;
};

}  // namespace

std::vector<std::pair<std::pair<int, int>, int>> EdgeUses(const std::vector<Triangle>& triangles,
                                                          const std::vector<char>& alive) {
  std::vector<std::pair<std::pair<int, int>, int>> uses;
  EdgeUses(triangles, alive, nullptr, &uses);
  return uses;
}

bool EdgeUses(const std::vector<Triangle>& triangles, const std::vector<char>& alive,
              const CancelToken* cancel, std::vector<std::pair<std::pair<int, int>, int>>* uses) {
  // Equal b's in a bucket (ForEachBucket) are one edge's uses.
  int n = 0;
  size_t live = 0;
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (t % 4096 == 0 && Cancelled(cancel)) return false;
    if (!alive[t]) continue;
    ++live;
    n = std::max({n, triangles[t][0] + 1, triangles[t][1] + 1, triangles[t][2] + 1});
  }
  auto for_each_edge = [&](auto&& emit) {
    for (size_t t = 0; t < triangles.size(); ++t) {
      if (t % 4096 == 0 && Cancelled(cancel)) return false;
      if (!alive[t]) continue;
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = std::minmax(triangles[t][k], triangles[t][(k + 1) % 3]);
        emit(a, b);
      }
    }
    return true;
  };
  uses->clear();
  uses->reserve(3 * live / 2 + 1);  // interior edges have two uses
  return ForEachBucket(
      n, for_each_edge,
      [&](int a, auto begin, auto end) {
        for (auto i = begin; i != end;) {
          auto j = i;
          while (j != end && *j == *i) ++j;
          uses->push_back({{a, *i}, static_cast<int>(j - i)});
          i = j;
        }
      },
      cancel);
}

double WorstQuality(const Multimesh& mesh) {
  double worst = 1.0;
  for (const Points& x : mesh.shapes)
    worst = std::min(worst, WorstTriangleQuality(mesh.triangles, x));
  return worst;
}

bool StrictlyInsideSegment(const Point& a, const Point& b, const Point& v) {
  // The turn at v (sine, from the cross product of av and vb) rather than v's distance from the
  // line relative to |ab|: a corner whose neighbour has slid to within 1e-9 |ab| of it is off
  // that line by less than that and was taken for straight, then slid or collapsed away.
  const Point av = v - a, vb = b - v;
  return av.dot(vb) > 0.0 && std::abs(Cross(av, vb)) <= 1e-9 * av.norm() * vb.norm();
}

absl::StatusOr<Multimesh> ImproveTopology(const Multimesh& mesh, double map_weight,
                                          const TopologyOptions& options, TopologyReport* report,
                                          const CancelToken* cancel,
                                          const std::vector<ShapeOutline>* outlines) {
  // Polled before every candidate operation (a relaxed atomic load; a pass on 35k vertices takes
  // ~0.1 s, more than the 100 ms a cancel may take).
  const absl::Status cancelled_status = absl::CancelledError("comesh topology pass cancelled");
  absl::StatusOr<ComeshObjective> objective =
      ComeshObjective::Create(mesh.triangles, mesh.shapes, map_weight);
  if (!objective.ok()) return objective.status();
  if (Cancelled(cancel)) return cancelled_status;
  Editor editor(mesh, *objective, options, outlines, cancel);
  if (editor.cancelled() || Cancelled(cancel)) return cancelled_status;
  TopologyReport rep;
  rep.objective_before = editor.Objective();
  if (!std::isfinite(rep.objective_before)) {
    return absl::InvalidArgumentError("ImproveTopology: a triangle is not positive in some shape");
  }
  // Flip sweeps: the first over every interior edge (all_edges) or over the edges at vertices
  // changed since the last sweep, each later one over the edges at the vertices the previous
  // sweep changed (an edge whose two triangles and corners did not change would be refused
  // again, up to the acceptance threshold's dependence on the whole objective and an edge between
  // its opposite corners removed elsewhere; the next pass sees those), until a sweep flips
  // nothing or flip_sweeps were made.
  auto flip_sweeps = [&](bool all_edges) {
    for (int sweep = 0; options.flips && sweep < options.flip_sweeps; ++sweep) {
      const bool everything = all_edges && sweep == 0;
      std::vector<std::pair<int, int>> edges;
      if (!(everything ? editor.InteriorEdges(cancel, &edges)
                       : editor.InteriorEdgesAt(editor.TakeDirty(), cancel, &edges))) {
        return false;
      }
      if (everything) editor.TakeDirty();
      int flips = 0;
      for (const auto& [a, b] : edges) {
        if (Cancelled(cancel)) return false;
        flips += editor.TryFlip(a, b);
      }
      rep.flips += flips;
      if (flips == 0) break;
    }
    return true;
  };
  if (!flip_sweeps(/*all_edges=*/true)) return cancelled_status;
  // The interior edges with sign * r < sign * ratio, r their relative length (max over shapes),
  // as (sign * r, edge) ascending: sign +1 lists the shortest first below a ratio (collapses),
  // -1 the longest first above it (splits); false if cancelled.
  std::vector<std::pair<int, int>> interior;
  std::vector<std::pair<double, std::pair<int, int>>> candidates;
  auto candidates_by = [&](double sign, double ratio) {
    if (!editor.InteriorEdges(cancel, &interior)) return false;
    candidates.clear();
    for (size_t i = 0; i < interior.size(); ++i) {
      if (i % 4096 == 0 && Cancelled(cancel)) return false;
      const auto [a, b] = interior[i];
      const double key = sign * editor.RelativeLength(a, b, /*max=*/true);
      if (key < sign * ratio) candidates.push_back({key, {a, b}});
    }
    std::sort(candidates.begin(), candidates.end());
    return !Cancelled(cancel);
  };
  if (options.collapses) {
    if (!candidates_by(+1.0, options.collapse_ratio)) return cancelled_status;
    if (options.boundary_collapses) {
      for (const auto& [a, b] : editor.BoundaryCollapseEdges()) {
        // A corner swap is tried whatever its length: sliding cannot do its work.
        const double key = editor.RelativeLength(a, b, /*max=*/true);
        if (key < options.collapse_ratio || !editor.Removable(a, b)) {
          candidates.push_back({key, {a, b}});
        }
      }
      std::sort(candidates.begin(), candidates.end());
    }
    for (const auto& [r, edge] : candidates) {
      if (Cancelled(cancel)) return cancelled_status;
      rep.collapses += editor.TryCollapse(edge.first, edge.second) ||
                       editor.TryCollapse(edge.second, edge.first);
    }
  }
  if (options.splits) {
    if (!candidates_by(-1.0, options.split_ratio)) return cancelled_status;
    if (options.boundary_splits) {
      for (const auto& [a, b] : editor.SplittableBoundaryEdges()) {
        const double key = -editor.RelativeLength(a, b, /*max=*/true);
        if (key < -options.split_ratio) candidates.push_back({key, {a, b}});
      }
      std::sort(candidates.begin(), candidates.end());
    }
    for (const auto& [r, edge] : candidates) {
      if (Cancelled(cancel)) return cancelled_status;
      rep.splits += editor.TrySplit(edge.first, edge.second);
    }
  }
  if (rep.collapses + rep.splits > 0 && !flip_sweeps(/*all_edges=*/false)) {
    return cancelled_status;
  }
  rep.objective_after = editor.Objective();
  rep.corner_swaps = editor.corner_swaps();
  if (report != nullptr) *report = rep;
  return editor.Compact(mesh);
}

absl::StatusOr<Multimesh> RemoveSlivers(const Multimesh& mesh, double map_weight,
                                        double min_quality, SliverReport* report,
                                        const CancelToken* cancel,
                                        const std::vector<ShapeOutline>* outlines,
                                        const Multimesh* anchor_mesh) {
  const absl::Status cancelled_status = absl::CancelledError("comesh sliver removal cancelled");
  std::vector<Points> anchors;
  if (anchor_mesh != nullptr) {
    for (const Points& x : anchor_mesh->shapes) {
      Points& a = anchors.emplace_back();
      for (int v : anchor_mesh->boundary) a.push_back(x[v]);
      std::sort(a.begin(), a.end(), LexicographicLess);
    }
  }
  absl::StatusOr<ComeshObjective> objective =
      ComeshObjective::Create(mesh.triangles, mesh.shapes, map_weight);
  if (!objective.ok()) return objective.status();
  // Every operation must raise the worst quality of the triangles it changes, so new triangles
  // need only be positive: the min_area_ratio rule would refuse to touch the thin triangles a
  // drawing's own sharp spike needs (pentagon -> star).
  TopologyOptions options;
  options.min_area_ratio = 0.0;
  Editor editor(mesh, *objective, options, outlines, cancel);
  if (editor.cancelled() || Cancelled(cancel)) return cancelled_status;
  if (anchor_mesh != nullptr) editor.set_anchors(&anchors);
  SliverReport rep;
  rep.worst_quality_before = WorstQuality(mesh);
  // Each sweep touches a sliver's neighbourhood once (locks); a later sweep takes what an earlier
  // one left or made.
  for (int sweep = 0; sweep < kSliverSweeps; ++sweep) {
    const std::vector<int> slivers = editor.Slivers(min_quality);
    if (sweep == 0) rep.slivers_before = static_cast<int>(slivers.size());
    int changed = 0;
    for (int t : slivers) {
      if (Cancelled(cancel)) return cancelled_status;
      changed += editor.TryRemoveSliver(t);
    }
    rep.operations += changed;
    editor.Unlock();
    if (changed == 0) break;
  }
  rep.slivers_after = static_cast<int>(editor.Slivers(min_quality).size());
  rep.snaps = editor.snaps();
  Multimesh out = editor.Compact(mesh);
  rep.worst_quality_after = WorstQuality(out);
  // Boundary lists that could not be traced (a vertex with more than two boundary edges) are
  // patched from the input's, which several boundary operations at one place can defeat: then
  // nothing is changed rather than a broken multimesh handed on.
  if (rep.operations > 0 && !ValidateMultimesh(out).ok()) {
    rep.slivers_after = rep.slivers_before;
    rep.worst_quality_after = rep.worst_quality_before;
    rep.operations = rep.snaps = 0;
    out = mesh;
  }
  if (report != nullptr) *report = rep;
  return out;
}

}  // namespace inbetween::solver
