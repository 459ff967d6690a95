#include "solver/mesh/overlay_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <queue>
#include <set>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "solver/core/error_reason.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/cgal_predicates.h"
#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/collapse_vertices.h"
#include "solver/mesh/map_to_boundary.h"
#include "solver/mesh/split_boundary_chords.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

// The chord triangulation of the new drawing, by boundary loop position k (0..nb-1).
struct Chords {
  std::vector<std::array<int, 2>> ends;        // chord -> its two loop positions, ascending
  std::vector<std::array<int, 2>> faces;       // chord -> the two triangles it separates
  std::vector<std::array<int, 3>> corners;     // triangle -> loop positions, counter-clockwise
  std::vector<std::array<int, 3>> side_chord;  // triangle -> chord opposite corner k (-1: rim)
};

// The chords of a triangulation of the loop's polygon without interior points, its triangles
// given by loop position.
Chords ChordsOf(const std::vector<std::array<int, 3>>& by_position, int nb) {
  Chords chords;
  std::map<std::pair<int, int>, int> id;
  for (size_t t = 0; t < by_position.size(); ++t) {
    const std::array<int, 3>& tri = by_position[t];
    chords.corners.push_back(tri);
    std::array<int, 3> sides{-1, -1, -1};
    for (int k = 0; k < 3; ++k) {
      const int a = tri[(k + 1) % 3], b = tri[(k + 2) % 3];
      if ((a + 1) % nb == b || (b + 1) % nb == a) continue;  // a polygon edge
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      auto [it, inserted] = id.emplace(key, static_cast<int>(chords.ends.size()));
      if (inserted) {
        chords.ends.push_back({key.first, key.second});
        chords.faces.push_back({static_cast<int>(t), -1});
      } else {
        chords.faces[it->second][1] = static_cast<int>(t);
      }
      sides[k] = it->second;
    }
    chords.side_chord.push_back(sides);
  }
  return chords;
}

absl::StatusOr<Chords> TriangulatePolygon(const Points& polygon) {
  TriangulateOptions options;
  options.refine = false;
  absl::StatusOr<PolygonTriangulation> cdt = CgalTriangulate(polygon, options);
  if (!cdt.ok()) return cdt.status();
  const int nb = static_cast<int>(polygon.size());
  if (static_cast<int>(cdt->vertices.size()) != nb) {
    return absl::InternalError("overlay: the polygon's triangulation added points");
  }
  std::vector<std::array<int, 3>> by_position;
  for (const Triangle& t : cdt->triangles) by_position.push_back({t[0], t[1], t[2]});
  return ChordsOf(by_position, nb);
}

// Directed edge a -> b -> the triangle that has it counter-clockwise.
std::map<std::pair<int, int>, int> LeftOf(const std::vector<Triangle>& triangles) {
  std::map<std::pair<int, int>, int> left;
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      left[{triangles[t][k], triangles[t][(k + 1) % 3]}] = static_cast<int>(t);
    }
  }
  return left;
}

// The triangles around v counter-clockwise from the one left of v -> from, up to the one whose
// next edge is v -> to (included), or up to the boundary (to < 0). Empty if v -> from has no
// triangle on its left or the turn does not end (a broken fan).
std::vector<int> Turn(const std::vector<Triangle>& triangles,
                      const std::map<std::pair<int, int>, int>& left, int v, int from, int to) {
  std::vector<int> fan;
  for (int w = from; fan.size() <= triangles.size();) {
    auto it = left.find({v, w});
    if (it == left.end()) return to < 0 && !fan.empty() ? fan : std::vector<int>{};
    const Triangle& t = triangles[it->second];
    fan.push_back(it->second);
    const int k = t[0] == v ? 0 : t[1] == v ? 1 : 2;
    w = t[(k + 2) % 3];
    if (w == to) return fan;
  }
  return {};
}

// The triangles of the domain a loop of points bounds, by loop position. Points may repeat (a
// slit or a closed cut walked both ways): each triangle corner at such a point belongs to the
// visit whose sector, counter-clockwise from the next point to the previous one, holds it.
absl::StatusOr<std::vector<std::array<int, 3>>> TriangulateLoop(const Points& loop) {
  TriangulateOptions options;
  options.refine = false;
  absl::StatusOr<DomainTriangulation> cdt = CgalTriangulateDomain({loop}, options);
  if (!cdt.ok()) return cdt.status();
  const int nb = static_cast<int>(loop.size());
  const std::vector<int>& at = cdt->loop_vertex[0];
  std::vector<std::vector<int>> visits(cdt->vertices.size());
  for (int k = 0; k < nb; ++k) visits[at[k]].push_back(k);
  const auto broken = [] {
    return absl::FailedPreconditionError(
        "overlay: the drawing's outline, cut open, does not bound one disk");
  };
  // A triangulated disk whose vertices are all on its boundary: nb - 2 triangles.
  if (static_cast<int>(cdt->triangles.size()) != nb - 2) return broken();
  const std::map<std::pair<int, int>, int> left = LeftOf(cdt->triangles);
  std::vector<std::array<int, 3>> out(cdt->triangles.size(), {-1, -1, -1});
  for (size_t t = 0; t < out.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::vector<int>& v = visits[cdt->triangles[t][k]];
      if (v.empty()) return broken();
      if (v.size() == 1) out[t][k] = v[0];
    }
  }
  for (int k = 0; k < nb; ++k) {
    const int v = at[k];
    if (visits[v].size() == 1) continue;
    for (int t : Turn(cdt->triangles, left, v, at[(k + 1) % nb], at[(k + nb - 1) % nb])) {
      const Triangle& tri = cdt->triangles[t];
      const int c = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
      if (out[t][c] >= 0) return broken();
      out[t][c] = k;
    }
  }
  for (const auto& t : out) {
    if (t[0] < 0 || t[1] < 0 || t[2] < 0) return broken();
  }
  return out;
}

// What a polygon edge lies on during the splitting: a mesh edge u -> v, or a chord.
struct Support {
  int u = -1, v = -1;  // mesh edge (chord < 0)
  int chord = -1;
};

struct Crossing {
  int u, v;  // the mesh edge, u < v
  int chord;
  double t;  // along u -> v
  double s;  // along the chord, from its first end to its second
};

class Overlay {
 public:
  Overlay(const std::vector<Triangle>& triangles, const std::vector<int>& boundary,
          const Points& disk, const Points& circle, const Chords& chords)
      : triangles_(triangles),
        disk_(disk),
        circle_(circle),
        chords_(chords),
        n_(static_cast<int>(disk.size())) {
    loop_position_.assign(n_, -1);
    for (size_t k = 0; k < boundary.size(); ++k) loop_position_[boundary[k]] = static_cast<int>(k);
    // Each chord's bounding box, for the candidate test.
    for (const auto& e : chords.ends) {
      const Point& p = circle[e[0]];
      const Point& q = circle[e[1]];
      box_lo_.push_back(p.cwiseMin(q));
      box_hi_.push_back(p.cwiseMax(q));
    }
  }

  // The side of vertex x (an input vertex, or n_ + crossing index) of chord c: +1 left of
  // ends[0] -> ends[1], -1 right, 0 on it.
  int Side(int x, int c) const {
    const auto& e = chords_.ends[c];
    if (x < n_) {
      const int k = loop_position_[x];
      if (k == e[0] || k == e[1]) return 0;
      const Point& p = k >= 0 ? circle_[k] : disk_[x];
      return ExactOrientation(circle_[e[0]], circle_[e[1]], p);
    }
    const Crossing& cr = crossings_[x - n_];
    if (cr.chord == c) return 0;
    // Chords do not cross: the crossing is on the side of c where its chord's other end is.
    const auto& f = chords_.ends[cr.chord];
    const int a = f[0] == e[0] || f[0] == e[1]
                      ? 0
                      : ExactOrientation(circle_[e[0]], circle_[e[1]], circle_[f[0]]);
    const int b = f[1] == e[0] || f[1] == e[1]
                      ? 0
                      : ExactOrientation(circle_[e[0]], circle_[e[1]], circle_[f[1]]);
    return a != 0 ? a : b;
  }

  // Splits every triangle by the chords crossing it; the cells, fanned later, and the chord
  // triangle each cell lies in.
  absl::Status Run(const CancelToken* cancel, int max_vertices) {
    for (size_t t = 0; t < triangles_.size(); ++t) {
      if ((t & 1023) == 0 && Cancelled(cancel)) return absl::CancelledError("overlay cancelled");
      if (max_vertices > 0 && num_vertices() > max_vertices) {
        return WithReason(absl::ResourceExhaustedError(absl::StrCat(
                              "overlay: the refinement needs more than ", max_vertices,
                              " vertices")),
                          kReasonMeshVertexLimit);
      }
      const Triangle& tri = triangles_[t];
      Point lo = disk_[tri[0]], hi = lo;
      for (int k = 1; k < 3; ++k) lo = lo.cwiseMin(disk_[tri[k]]), hi = hi.cwiseMax(disk_[tri[k]]);
      std::vector<Polygon> cells(1);
      for (int k = 0; k < 3; ++k) {
        cells[0].vertices.push_back(tri[k]);
        cells[0].supports.push_back({tri[k], tri[(k + 1) % 3], -1});
      }
      for (size_t c = 0; c < chords_.ends.size(); ++c) {
        if (box_hi_[c].x() < lo.x() || box_lo_[c].x() > hi.x() || box_hi_[c].y() < lo.y() ||
            box_lo_[c].y() > hi.y()) {
          continue;
        }
        std::vector<Polygon> next;
        for (Polygon& cell : cells) {
          absl::Status split = Split(cell, static_cast<int>(c), &next);
          if (!split.ok()) return split;
        }
        cells = std::move(next);
      }
      for (Polygon& cell : cells) {
        const int face = Locate([&](int c) {
          for (int x : cell.vertices) {
            if (const int s = Side(x, c); s != 0) return s;
          }
          return 0;
        });
        cells_.push_back({std::move(cell.vertices), face});
      }
    }
    return absl::OkStatus();
  }

  int num_vertices() const { return n_ + static_cast<int>(crossings_.size()); }
  // Input vertex v's position along the boundary loop (-1: interior).
  int LoopPosition(int v) const { return loop_position_[v]; }
  const std::vector<Crossing>& crossings() const { return crossings_; }
  struct Cell {
    std::vector<int> vertices;  // counter-clockwise
    int face;                   // the chord triangle it lies in
  };
  const std::vector<Cell>& cells() const { return cells_; }

  // The chord triangle holding input vertex x (any of them when x is on a chord).
  int LocateVertex(int x) {
    return Locate([&](int c) { return Side(x, c); });
  }

 private:
  struct Polygon {
    std::vector<int> vertices;
    std::vector<Support> supports;  // supports[i]: the edge from vertices[i] to the next
  };

  // Walks the dual tree of the chord triangles from the last answer to the triangle whose
  // chords all have the point (given by its side of each chord) on their inner side.
  template <class SideOf>
  int Locate(const SideOf& side_of) {
    int face = hint_;
    for (size_t steps = 0; steps <= chords_.corners.size(); ++steps) {
      bool moved = false;
      for (int k = 0; k < 3 && !moved; ++k) {
        const int c = chords_.side_chord[face][k];
        if (c < 0) continue;
        const int inner = ExactOrientation(circle_[chords_.ends[c][0]], circle_[chords_.ends[c][1]],
                                           circle_[chords_.corners[face][k]]);
        const int s = side_of(c);
        if (s != 0 && s != inner) {
          const auto& f = chords_.faces[c];
          face = f[0] == face ? f[1] : f[0];
          moved = true;
        }
      }
      if (!moved) break;
    }
    hint_ = face;
    return face;
  }

  int CrossingOf(const Support& edge, int c) {
    const int u = std::min(edge.u, edge.v), v = std::max(edge.u, edge.v);
    auto [it, inserted] = crossing_index_.emplace(std::make_tuple(u, v, c), num_vertices());
    if (inserted) {
      const Point& p0 = disk_[u];
      const Point d1 = disk_[v] - p0;
      const Point& q0 = circle_[chords_.ends[c][0]];
      const Point d2 = circle_[chords_.ends[c][1]] - q0;
      const Point r = q0 - p0;
      const double denom = Cross(d1, d2);
      const double t = std::clamp(Cross(r, d2) / denom, 0.0, 1.0);
      const double s = std::clamp(Cross(r, d1) / denom, 0.0, 1.0);
      crossings_.push_back({u, v, c, t, s});
    }
    return it->second;
  }

  // Sutherland-Hodgman on both sides of chord c, appending the pieces to `out`.
  absl::Status Split(const Polygon& cell, int c, std::vector<Polygon>* out) {
    const int m = static_cast<int>(cell.vertices.size());
    std::vector<int> side(m);
    bool positive = false, negative = false;
    for (int i = 0; i < m; ++i) {
      side[i] = Side(cell.vertices[i], c);
      positive |= side[i] > 0;
      negative |= side[i] < 0;
    }
    if (!positive || !negative) {
      out->push_back(cell);
      return absl::OkStatus();
    }
    std::array<Polygon, 2> piece;  // [0]: left of the chord, [1]: right
    const Support along{-1, -1, c};
    for (int i = 0; i < m; ++i) {
      const int j = (i + 1) % m;
      const int a = cell.vertices[i];
      const Support& edge = cell.supports[i];
      for (int h = 0; h < 2; ++h) {
        const int sa = h == 0 ? side[i] : -side[i];
        const int sb = h == 0 ? side[j] : -side[j];
        Polygon& p = piece[h];
        if (sa > 0 || (sa == 0 && sb >= 0)) {
          p.vertices.push_back(a);
          p.supports.push_back(edge);
        } else if (sa == 0) {  // sb < 0: this piece leaves a along the chord
          p.vertices.push_back(a);
          p.supports.push_back(along);
        }
        if (sa != 0 && sb != 0 && sa != sb) {
          if (edge.chord >= 0) {
            return absl::InternalError("overlay: two chords of a triangulation cross");
          }
          const int x = CrossingOf(edge, c);
          if (sa > 0) {  // leaving this side: the next edge runs along the chord
            p.vertices.push_back(x);
            p.supports.push_back(along);
          } else {  // entering: from x along the rest of the edge
            p.vertices.push_back(x);
            p.supports.push_back(edge);
          }
        }
      }
    }
    for (Polygon& p : piece) {
      if (p.vertices.size() >= 3) out->push_back(std::move(p));
    }
    return absl::OkStatus();
  }

  const std::vector<Triangle>& triangles_;
  const Points& disk_;
  const Points& circle_;
  const Chords& chords_;
  const int n_;
  std::vector<int> loop_position_;
  std::vector<Point> box_lo_, box_hi_;
  std::vector<Crossing> crossings_;
  std::map<std::tuple<int, int, int>, int> crossing_index_;
  std::vector<Cell> cells_;
  int hint_ = 0;
};

bool StrictlyConvex(const Points& polygon) {
  const size_t n = polygon.size();
  for (size_t k = 0; k < n; ++k) {
    if (ExactOrientation(polygon[k], polygon[(k + 1) % n], polygon[(k + 2) % n]) <= 0) return false;
  }
  return true;
}

// The mesh cut open along paths into a disk.
struct Opened {
  std::vector<Triangle> triangles;
  std::vector<int> original;  // vertex of the opened mesh -> the input vertex it stands for
  std::vector<int> loop;      // its one boundary loop, from `start`, interior on the left
};

// Cuts the mesh (vertices 0..n-1, counter-clockwise triangles) along each path (vertex-disjoint
// paths of edges between two boundary vertices, interior vertices between them): every vertex
// of a path gets a copy (n, n + 1, ... in path order), used by the triangles on the path's
// right. FAILED_PRECONDITION unless the result is one disk.
absl::StatusOr<Opened> CutOpen(const std::vector<Triangle>& triangles, int n,
                               const std::vector<std::vector<int>>& paths, int start) {
  const auto broken = [] {
    return absl::FailedPreconditionError("overlay: cutting the holes open did not give a disk");
  };

  const std::map<std::pair<int, int>, int> left = LeftOf(triangles);
  std::vector<std::vector<int>> around(n);
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int v : triangles[t]) around[v].push_back(static_cast<int>(t));
  }
  Opened o;
  o.triangles = triangles;
  for (int v = 0; v < n; ++v) o.original.push_back(v);
  for (const std::vector<int>& path : paths) {
    const int m = static_cast<int>(path.size()) - 1;
    if (m < 1) return broken();
    for (int i = 0; i <= m; ++i) {
      const int v = path[i];
      std::vector<int> right;
      if (i == 0) {  // right of the path: all but the turn from it to the boundary
        const std::vector<int> l = Turn(triangles, left, v, path[1], -1);
        if (l.empty()) return broken();
        for (int t : around[v]) {
          if (std::find(l.begin(), l.end(), t) == l.end()) right.push_back(t);
        }
      } else {
        right = Turn(triangles, left, v, path[i - 1], i < m ? path[i + 1] : -1);
      }
      if (right.empty()) return broken();
      const int copy = static_cast<int>(o.original.size());
      o.original.push_back(v);
      for (int t : right) {
        for (int& x : o.triangles[t]) {
          if (x == v) x = copy;
        }
      }
    }
  }
  // One boundary loop, and Euler's characteristic of a disk.
  std::set<std::pair<int, int>> edges;
  for (const Triangle& t : o.triangles) {
    for (int k = 0; k < 3; ++k) edges.emplace(t[k], t[(k + 1) % 3]);
  }
  std::map<int, int> next;
  for (const auto& [a, b] : edges) {
    if (!edges.count({b, a}) && !next.emplace(a, b).second) return broken();
  }
  for (int v = start; o.loop.size() <= next.size();) {
    o.loop.push_back(v);
    auto it = next.find(v);
    if (it == next.end()) return broken();
    if ((v = it->second) == start) break;
  }
  const long long faces = static_cast<long long>(o.triangles.size());
  std::set<int> used;
  for (const Triangle& t : o.triangles) used.insert(t.begin(), t.end());
  const long long vertices = static_cast<long long>(used.size());
  const long long boundary_edges = static_cast<long long>(next.size());
  if (o.loop.size() != next.size() || vertices - (3 * faces + boundary_edges) / 2 + faces != 1) {
    return broken();
  }
  return o;
}

constexpr long long kPreMergeFactor = 4;
constexpr long long kMaxPreMergeVertices = 2'000'000;

// Placements of the boundary on the circle, tried in turn: the share of the first shape's arc
// length blended with even spacing. The spacing decides where chords pass close to mesh
// vertices and cut thin pieces. Even spacing first: arc length crowds short boundary edges,
// whose chords then graze the vertices between them.
constexpr double kCircleBlends[] = {0.0, 0.5, 0.9, 0.25, 0.75, 0.6};
// The first placement whose worst triangle is at least this good is kept, else the best.
constexpr double kGoodQuality = 1e-3;

// The bound on the refinement before the merges: the bound is on the result, after them (which
// take about two in three crossings), so the refinement may have kPreMergeFactor times as many
// vertices, up to kMaxPreMergeVertices (0: no bound).
int RefineBound(int max_vertices) {
  return max_vertices <= 0
             ? 0
             : static_cast<int>(std::max<long long>(
                   max_vertices,
                   std::min<long long>(kPreMergeFactor * static_cast<long long>(max_vertices),
                                       kMaxPreMergeVertices)));
}

absl::Status TooManyVertices(int max_vertices) {
  return WithReason(absl::ResourceExhaustedError(absl::StrCat(
                        "overlay: the refinement needs more than ", max_vertices, " vertices")),
                    kReasonMeshVertexLimit);
}

// The worst triangle quality of the result over every drawing (4 sqrt(3) area / sum of squared
// edges: 1 equilateral), or -1 when a triangle is not positive in doubles, as every later stage
// judges a triangle (validate.h's CountInverted).
double WorstQuality(const OverlayResult& result) {
  double worst = std::numeric_limits<double>::infinity();
  for (const Points& s : result.shapes) {
    worst = std::min(worst, CountInverted(result.triangles, s) == 0
                                ? WorstTriangleQuality(result.triangles, s)
                                : -1.0);
  }
  return worst;
}

// The fan apex of a convex cell (vertices counter-clockwise) that keeps its smallest triangle
// largest, relative to the cell's area, over every drawing; 0 for a triangle.
int BestApex(const std::vector<int>& cell, const std::vector<Points>& shapes) {
  const int m = static_cast<int>(cell.size());
  int best = 0;
  double best_worst = -std::numeric_limits<double>::infinity();
  for (int apex = 0; apex < m && m > 3; ++apex) {
    double worst = std::numeric_limits<double>::infinity();
    for (const Points& s : shapes) {
      double cell_area = 0.0;
      for (int i = 1; i + 1 < m; ++i) {
        cell_area += Cross(s[cell[i]] - s[cell[0]], s[cell[i + 1]] - s[cell[0]]);
      }
      const Point& o = s[cell[apex]];
      for (int i = 1; i + 1 < m; ++i) {
        const Point& p = s[cell[(apex + i) % m]];
        const Point& q = s[cell[(apex + i + 1) % m]];
        worst = std::min(worst, Cross(p - o, q - o) / std::abs(cell_area));
      }
    }
    if (worst > best_worst) best_worst = worst, best = apex;
  }
  return best;
}

// OverlayDisk's inputs and its phases for one placement of the boundary on the circle (Try):
// the circle, the convex (Tutte) embedding on it, the overlay, every vertex placed in every
// drawing, the cells fanned, the cut's copies glued back and the crossings merged where they
// may be. A class because every phase reads the same inputs.
class DiskOverlay {
 public:
  // A placement's outcome: the refinement, or why it failed. A fatal failure (cancelled, out of
  // memory, a broken overlay, an error merging) ends the search; the others leave it to the next
  // placement.
  struct Outcome {
    absl::StatusOr<OverlayResult> result;
    bool fatal = false;
  };

  DiskOverlay(const std::vector<Triangle>& triangles, const std::vector<Points>& shapes,
              const std::vector<int>& boundary, const Points& target_boundary, const Chords& chords,
              const std::vector<int>& original, int kept, int fixed, const CancelToken* cancel,
              int max_vertices)
      : triangles_(triangles),
        shapes_(shapes),
        boundary_(boundary),
        target_(target_boundary),
        chords_(chords),
        original_(original),
        kept_(kept),
        fixed_(fixed),
        cancel_(cancel),
        max_vertices_(max_vertices),
        refine_bound_(RefineBound(max_vertices)),
        m_(static_cast<int>(shapes[0].size())),
        nb_(static_cast<int>(boundary.size())),
        arc_(nb_ + 1, 0.0) {
    for (int k = 0; k < nb_; ++k) {
      arc_[k + 1] = arc_[k] + (shapes[0][boundary[(k + 1) % nb_]] - shapes[0][boundary[k]]).norm();
    }
  }

  // Placement `attempt` (an index into kCircleBlends), start to end.
  Outcome Try(int attempt) const {
    const Points circle = Circle(attempt);
    if (!StrictlyConvex(circle)) {
      return {absl::FailedPreconditionError("overlay: the circle's points are not convex")};
    }
    absl::StatusOr<Points> disk = Embed(circle);
    if (!disk.ok()) {
      return {disk.status(),
              absl::IsCancelled(disk.status()) || absl::IsResourceExhausted(disk.status())};
    }
    Overlay overlay(triangles_, boundary_, *disk, circle, chords_);
    if (absl::Status run = overlay.Run(cancel_, refine_bound_); !run.ok()) {
      return {absl::IsResourceExhausted(run) ? TooManyVertices(max_vertices_) : run, true};
    }
    OverlayResult result = PlaceVertices(overlay, circle, *disk);
    // Each convex cell fanned from its best apex (BestApex).
    for (const Overlay::Cell& cell : overlay.cells()) {
      const int m = static_cast<int>(cell.vertices.size());
      const int apex = BestApex(cell.vertices, result.shapes);
      for (int i = 1; i + 1 < m; ++i) {
        result.triangles.push_back({cell.vertices[apex], cell.vertices[(apex + i) % m],
                                    cell.vertices[(apex + i + 1) % m]});
      }
    }
    GlueCopies(&result);
    result.added_vertices = static_cast<int>(result.shapes[0].size()) - fixed_;
    if (absl::Status merged = MergeCrossings(&result); !merged.ok()) return {merged, true};
    if (max_vertices_ > 0 && fixed_ + result.added_vertices > max_vertices_) {
      return {TooManyVertices(max_vertices_)};  // another placement may cut fewer pieces
    }
    return {std::move(result)};
  }

 private:
  // The boundary's points on the unit circle for placement `attempt`, each also moved by a
  // pseudo-random fraction of under a quarter of the even step (symmetric drawings put mesh
  // vertices on chords otherwise); some even share keeps every step positive.
  Points Circle(int attempt) const {
    const double blend = arc_[nb_] > 0 ? kCircleBlends[attempt] : 0.0;
    std::uint64_t state = 0x9E3779B97F4A7C15ull * (attempt + 1);
    Points circle(nb_);
    for (int k = 0; k < nb_; ++k) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const double jitter = 0.2 * ((state >> 11) * 0x1.0p-53 - 0.5) * (1.0 - blend) / nb_;
      const double share =
          (arc_[nb_] > 0 ? blend * arc_[k] / arc_[nb_] : 0.0) + (1.0 - blend) * k / nb_ + jitter;
      const double angle = 2.0 * std::numbers::pi * share;
      circle[k] = Point(std::cos(angle), std::sin(angle));
    }
    return circle;
  }

  // The mesh's Tutte embedding with its boundary on the circle (no polish: the overlay needs the
  // convex combination map), checked to leave every triangle positive by the exact predicate.
  absl::StatusOr<Points> Embed(const Points& circle) const {
    MapToBoundaryOptions tutte;
    tutte.tutte_when_convex = true;
    tutte.polish_iterations = 0;
    absl::StatusOr<Points> disk =
        MapToBoundary(shapes_[0], triangles_, boundary_, circle, tutte, cancel_);
    if (!disk.ok()) return disk;
    bool embedded = true;
    for (const Triangle& t : triangles_) {
      embedded &= ExactOrientation((*disk)[t[0]], (*disk)[t[1]], (*disk)[t[2]]) > 0;
    }
    if (!embedded) {
      return absl::FailedPreconditionError("overlay: the convex embedding has a flat triangle");
    }
    return disk;
  }

  // Every vertex of the refinement in every drawing: the input's where they were, and in the
  // new drawing (last shape) on their loop position or by their barycentric coordinates in the
  // chord triangle holding them; the crossings on their mesh edge and on their chord.
  OverlayResult PlaceVertices(Overlay& overlay, const Points& circle, const Points& disk) const {
    OverlayResult result;
    const int total = overlay.num_vertices();
    result.shapes = shapes_;
    for (Points& s : result.shapes) s.resize(total);
    Points target(total);
    for (int v = 0; v < m_; ++v) {
      if (const int k = overlay.LoopPosition(v); k >= 0) {
        target[v] = target_[k];
        continue;
      }
      const auto& corners = chords_.corners[overlay.LocateVertex(v)];
      const Point& a = circle[corners[0]];
      const Point& b = circle[corners[1]];
      const Point& c = circle[corners[2]];
      const Point& p = disk[v];
      const double area = Cross(b - a, c - a);
      const double lb = Cross(p - a, c - a) / area, lc = Cross(b - a, p - a) / area;
      target[v] = (1.0 - lb - lc) * target_[corners[0]] + lb * target_[corners[1]] +
                  lc * target_[corners[2]];
    }
    for (size_t i = 0; i < overlay.crossings().size(); ++i) {
      const Crossing& x = overlay.crossings()[i];
      const int v = m_ + static_cast<int>(i);
      for (Points& s : result.shapes) s[v] = (1.0 - x.t) * s[x.u] + x.t * s[x.v];
      const auto& e = chords_.ends[x.chord];
      target[v] = (1.0 - x.s) * target_[e[0]] + x.s * target_[e[1]];
    }
    result.shapes.push_back(std::move(target));
    return result;
  }

  // With a cut (original_ not empty), its copies glued back to the vertices they stand for and
  // the crossings renumbered after the kept vertices.
  void GlueCopies(OverlayResult* result) const {
    if (original_.empty()) return;
    const auto glued = [&](int v) { return v < m_ ? original_[v] : kept_ + (v - m_); };
    for (Triangle& t : result->triangles) {
      for (int& v : t) v = glued(v);
    }
    for (Points& s : result->shapes) {
      Points g(s.begin(), s.begin() + kept_);
      g.insert(g.end(), s.begin() + m_, s.end());
      s = std::move(g);
    }
  }

  // Crossings that cut slivers off a mesh triangle (a chord passing near one of its vertices)
  // merge into a neighbour where that leaves every drawing's thinnest triangle no thinner
  // (collapse_vertices.h); the input's vertices stay.
  absl::Status MergeCrossings(OverlayResult* result) const {
    absl::StatusOr<CollapseResult> coarse =
        CollapseVertices(result->triangles, result->shapes, fixed_, CollapseOptions{}, cancel_);
    if (!coarse.ok()) return coarse.status();
    result->triangles = std::move(coarse->triangles);
    result->shapes = std::move(coarse->shapes);
    result->added_vertices -= coarse->removed;
    return absl::OkStatus();
  }

  const std::vector<Triangle>& triangles_;
  const std::vector<Points>& shapes_;
  const std::vector<int>& boundary_;
  const Points& target_;
  const Chords& chords_;
  const std::vector<int>& original_;
  const int kept_;
  const int fixed_;
  const CancelToken* cancel_;
  const int max_vertices_;
  const int refine_bound_;
  const int m_;   // vertices of the disk mesh
  const int nb_;  // boundary vertices
  // arc_[k]: the first shape's arc length along the boundary up to loop position k (k <= nb_).
  std::vector<double> arc_;
};

// The overlay proper: the disk mesh (vertices 0..m-1 in every shape, boundary loop `boundary`)
// with the chord triangulation of the new drawing (target[k]: where loop position k lies).
// original[v] (empty: v itself) is the vertex (< kept) disk vertex v stands for: copies made by
// a cut are glued back to it, so the result's vertices are the kept ones, then the crossings.
// Vertices from `fixed` on (the crossings, and vertices the caller added) may be merged away.
// Placements are tried in the order of kCircleBlends until one is good (kGoodQuality).
absl::StatusOr<OverlayResult> OverlayDisk(const std::vector<Triangle>& triangles,
                                          const std::vector<Points>& shapes,
                                          const std::vector<int>& boundary,
                                          const Points& target_boundary,
                                          const absl::StatusOr<Chords>& chords,
                                          const std::vector<int>& original, int kept, int fixed,
                                          const CancelToken* cancel, int max_vertices) {
  if (!chords.ok()) {
    return absl::Status(chords.status().code(),
                        absl::StrCat("overlay: ", chords.status().message()));
  }
  const DiskOverlay overlay(triangles, shapes, boundary, target_boundary, *chords, original, kept,
                            fixed, cancel, max_vertices);
  absl::Status last = absl::FailedPreconditionError("overlay: no attempt");
  std::optional<OverlayResult> best;
  double best_quality = 0.0;
  for (int attempt = 0;
       attempt < static_cast<int>(std::size(kCircleBlends)) && best_quality < kGoodQuality;
       ++attempt) {
    if (Cancelled(cancel)) return absl::CancelledError("overlay cancelled");
    DiskOverlay::Outcome outcome = overlay.Try(attempt);
    if (outcome.fatal) return outcome.result.status();
    if (!outcome.result.ok()) {
      last = outcome.result.status();
      continue;
    }
    const double worst = WorstQuality(*outcome.result);
    if (!(worst > 0)) {
      last = absl::FailedPreconditionError(
          "overlay: a cell is too thin for double precision in some drawing");
      continue;
    }
    if (worst > best_quality) best_quality = worst, best = *std::move(outcome.result);
  }
  if (best.has_value()) return *std::move(best);
  return last;
}

bool HasRepeatedPoints(const Points& points) {
  std::set<std::pair<double, double>> seen;
  for (const Point& p : points) {
    if (!seen.emplace(p.x(), p.y()).second) return true;
  }
  return false;
}

absl::Status CheckShapes(const std::vector<Points>& shapes, int* n) {
  if (shapes.empty()) return absl::InvalidArgumentError("overlay: no shape");
  *n = static_cast<int>(shapes[0].size());
  for (const Points& s : shapes) {
    if (static_cast<int>(s.size()) != *n) {
      return absl::InvalidArgumentError("overlay: shapes of different sizes");
    }
  }
  return absl::OkStatus();
}

constexpr double kCrowdedCost = 10.0;

// The shortest path (lengths in `source`) from boundary vertex `from` to boundary vertex `to`
// through interior vertices not yet used; empty if there is none.
std::vector<int> InteriorPath(const std::vector<std::vector<int>>& adjacent,
                              const std::vector<int>& loop_of, const std::vector<char>& used,
                              const Points& source, int from, int to) {
  const int n = static_cast<int>(source.size());
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<int> prev(n, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  dist[from] = 0.0;
  queue.emplace(0.0, from);
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    if (v == to) break;
    if (v != from && loop_of[v] >= 0) continue;
    for (int w : adjacent[v]) {
      if (w != to && (loop_of[w] >= 0 || used[w])) continue;
      // A path next to a boundary or another path would leave no interior vertex between them
      // for later paths to pass through: such steps cost kCrowdedCost times their length.
      bool crowded = false;
      for (int x : adjacent[w]) crowded |= x != from && x != to && (loop_of[x] >= 0 || used[x]);
      const double nd =
          d + (crowded && w != to ? kCrowdedCost : 1.0) * (source[w] - source[v]).norm();
      if (nd < dist[w]) dist[w] = nd, prev[w] = v, queue.emplace(nd, w);
    }
  }
  if (prev[to] < 0) return {};
  std::vector<int> path;
  for (int v = to; v >= 0; v = prev[v]) path.push_back(v);
  std::reverse(path.begin(), path.end());
  return path;
}

// Paths of mesh edges that join every loop to loop 0 (a tree of cuts): each between boundary
// vertices of two loops whose points in the new drawing are joined by an edge of the chord
// triangulation of its loops (so the cut is a straight segment inside that drawing), shortest
// such edges first, through interior vertices, no two paths sharing a vertex.
constexpr int kMaxSlitTries = 2048;
constexpr int kMaxSlitRestarts = 8;
constexpr int kMaxSplitLevels = 2;

absl::StatusOr<std::vector<std::vector<int>>> Slits(const std::vector<Triangle>& triangles,
                                                    const Points& source,
                                                    const std::vector<std::vector<int>>& loops,
                                                    const std::vector<Points>& target_loops,
                                                    const CancelToken* cancel) {
  TriangulateOptions options;
  options.refine = false;
  absl::StatusOr<DomainTriangulation> cdt = CgalTriangulateDomain(target_loops, options);
  if (!cdt.ok()) {
    return absl::Status(cdt.status().code(), absl::StrCat("overlay: ", cdt.status().message()));
  }
  // Triangulation vertex -> input vertex (-1: several share the point, e.g. a closed cut).
  std::vector<int> vertex_of(cdt->vertices.size(), -2);
  for (size_t l = 0; l < loops.size(); ++l) {
    for (size_t k = 0; k < loops[l].size(); ++k) {
      int& v = vertex_of[cdt->loop_vertex[l][k]];
      v = v == -2 || v == loops[l][k] ? loops[l][k] : -1;
    }
  }
  const int n = static_cast<int>(source.size());
  std::vector<int> loop_of(n, -1);
  for (size_t l = 0; l < loops.size(); ++l) {
    for (int v : loops[l]) loop_of[v] = static_cast<int>(l);
  }
  struct Candidate {
    double length;
    int a, b;
    bool operator<(const Candidate& o) const {
      return std::tie(length, a, b) < std::tie(o.length, o.a, o.b);
    }
  };
  std::set<Candidate> candidates;
  for (const Triangle& t : cdt->triangles) {
    for (int k = 0; k < 3; ++k) {
      const int ca = t[k], cb = t[(k + 1) % 3];
      const int a = vertex_of[ca], b = vertex_of[cb];
      if (a < 0 || b < 0 || loop_of[a] == loop_of[b]) continue;
      candidates.insert(
          {(cdt->vertices[ca] - cdt->vertices[cb]).norm(), std::min(a, b), std::max(a, b)});
    }
  }
  std::vector<std::vector<int>> adjacent(n);
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) adjacent[t[k]].push_back(t[(k + 1) % 3]);
    for (int k = 0; k < 3; ++k) adjacent[t[(k + 1) % 3]].push_back(t[k]);
  }
  for (std::vector<int>& a : adjacent) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  // Greedy, shortest first; when some loops are left that no path reaches any more (earlier
  // paths walled them off), again with their cuts routed first.
  std::vector<char> first(loops.size(), 0);
  int tries = 0, lonely = 0;
  for (int round = 0; round <= kMaxSlitRestarts; ++round) {
    std::vector<char> used(n, 0), joined(loops.size(), 0);
    joined[0] = 1;
    std::vector<std::vector<int>> paths;
    bool found = true;
    while (found && paths.size() + 1 < loops.size()) {
      found = false;
      for (int pass = 0; pass < 2 && !found; ++pass) {
        for (const Candidate& c : candidates) {
          const int la = loop_of[c.a], lb = loop_of[c.b];
          if (joined[la] == joined[lb] || used[c.a] || used[c.b]) continue;
          if (pass == 0 && !first[la] && !first[lb]) continue;
          if (Cancelled(cancel)) return absl::CancelledError("overlay cancelled");
          if (++tries > kMaxSlitTries) break;
          std::vector<int> path = InteriorPath(adjacent, loop_of, used, source, c.a, c.b);
          if (path.empty()) continue;
          for (int v : path) used[v] = 1;
          joined[la] = joined[lb] = 1;
          paths.push_back(std::move(path));
          found = true;
          break;
        }
      }
    }
    if (found) return paths;
    lonely = 0;
    while (joined[lonely]) ++lonely;
    bool again = false;
    for (size_t l = 0; l < loops.size(); ++l) {
      if (!joined[l] && !first[l]) first[l] = 1, again = true;
    }
    if (!again || tries > kMaxSlitTries) break;
  }
  const Point& at = target_loops[lonely][0];
  return absl::FailedPreconditionError(
      absl::StrCat("overlay: no cut through the mesh joins the boundary loop through (", at.x(),
                   ", ", at.y(), ") in the new drawing to the others"));
}

}  // namespace

absl::StatusOr<OverlayResult> OverlayOntoPolygon(const std::vector<Triangle>& triangles,
                                                 const std::vector<Points>& shapes,
                                                 const std::vector<int>& boundary,
                                                 const Points& target_boundary,
                                                 const CancelToken* cancel, int max_vertices) {
  if (shapes.empty() || boundary.size() < 3 || boundary.size() != target_boundary.size()) {
    return absl::InvalidArgumentError(absl::StrCat("overlay: ", shapes.size(), " shapes, ",
                                                   boundary.size(), " boundary vertices and ",
                                                   target_boundary.size(), " target points"));
  }
  int n = 0;
  if (absl::Status s = CheckShapes(shapes, &n); !s.ok()) return s;
  return OverlayDisk(triangles, shapes, boundary, target_boundary,
                     TriangulatePolygon(target_boundary), {}, n, n, cancel, max_vertices);
}

absl::StatusOr<OverlayResult> OverlayOntoDomain(const std::vector<Triangle>& triangles,
                                                const std::vector<Points>& shapes,
                                                const std::vector<std::vector<int>>& loops,
                                                const std::vector<Points>& target_loops,
                                                const CancelToken* cancel, int max_vertices) {
  int n = 0;
  if (absl::Status s = CheckShapes(shapes, &n); !s.ok()) return s;
  if (loops.empty() || loops.size() != target_loops.size()) {
    return absl::InvalidArgumentError(absl::StrCat("overlay: ", loops.size(), " loops and ",
                                                   target_loops.size(), " target loops"));
  }
  for (size_t l = 0; l < loops.size(); ++l) {
    if (loops[l].size() < 2 || loops[l].size() != target_loops[l].size()) {
      return absl::InvalidArgumentError(absl::StrCat("overlay: loop ", l + 1, " has ",
                                                     loops[l].size(), " vertices and ",
                                                     target_loops[l].size(), " target points"));
    }
    for (int v : loops[l]) {
      if (v < 0 || v >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("overlay: loop ", l + 1, " names vertex ", v, " of ", n));
      }
    }
  }
  if (loops.size() == 1 && !HasRepeatedPoints(target_loops[0])) {
    return OverlayOntoPolygon(triangles, shapes, loops[0], target_loops[0], cancel, max_vertices);
  }
  // The cuts; where they cannot pass each other, again on the mesh with the interior edges
  // between two boundary vertices split, then also those with one end on the boundary; those
  // vertices are new ones of the result (merged away where they may be).
  std::vector<Triangle> mesh = triangles;
  std::vector<Points> placed = shapes;
  std::vector<std::vector<int>> paths;
  for (int level = 0; loops.size() > 1; ++level) {
    absl::StatusOr<std::vector<std::vector<int>>> slits =
        Slits(mesh, placed[0], loops, target_loops, cancel);
    if (slits.ok()) {
      paths = *std::move(slits);
      break;
    }
    if (!absl::IsFailedPrecondition(slits.status()) || level == kMaxSplitLevels) {
      return slits.status();
    }
    std::vector<bool> on_boundary(placed[0].size(), false);
    for (const std::vector<int>& loop : loops) {
      for (int v : loop) on_boundary[v] = true;
    }
    std::vector<Points*> each;
    for (Points& s : placed) each.push_back(&s);
    SplitInteriorEdges(each, &mesh, &on_boundary, kMaxSplitLevels - level);
  }
  const int kept = static_cast<int>(placed[0].size());
  absl::StatusOr<Opened> opened = CutOpen(mesh, kept, paths, loops[0][0]);
  if (!opened.ok()) return opened.status();
  // Where each vertex of the cut loop lies in the new drawing: its own point, or for a cut's
  // inner vertex, on the straight cut in the proportion of its arc length along the path.
  std::map<int, Point> where;
  for (size_t l = 0; l < loops.size(); ++l) {
    for (size_t k = 0; k < loops[l].size(); ++k) where[loops[l][k]] = target_loops[l][k];
  }
  for (const std::vector<int>& path : paths) {
    std::vector<double> arc(path.size(), 0.0);
    for (size_t i = 1; i < path.size(); ++i) {
      arc[i] = arc[i - 1] + (placed[0][path[i]] - placed[0][path[i - 1]]).norm();
    }
    const Point a = where.at(path.front()), b = where.at(path.back());
    for (size_t i = 1; i + 1 < path.size(); ++i) {
      const double s = arc[i] / arc.back();
      where[path[i]] = (1.0 - s) * a + s * b;
    }
  }
  Points loop_points;
  for (int v : opened->loop) loop_points.push_back(where.at(opened->original[v]));
  absl::StatusOr<std::vector<std::array<int, 3>>> by_position = TriangulateLoop(loop_points);
  absl::StatusOr<Chords> chords =
      by_position.ok()
          ? absl::StatusOr<Chords>(ChordsOf(*by_position, static_cast<int>(loop_points.size())))
          : absl::StatusOr<Chords>(by_position.status());
  for (Points& s : placed) {
    for (size_t v = kept; v < opened->original.size(); ++v) s.push_back(s[opened->original[v]]);
  }
  return OverlayDisk(opened->triangles, placed, opened->loop, loop_points, chords, opened->original,
                     kept, n, cancel, max_vertices);
}

}  // namespace inbetween::solver
