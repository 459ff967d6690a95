#include "solver/mesh/overlay_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "solver/mesh/cgal_predicates.h"
#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/collapse_vertices.h"
#include "solver/mesh/map_to_boundary.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

double Cross(const Point& a, const Point& b) { return a.x() * b.y() - a.y() * b.x(); }

// The chord triangulation of the new drawing, by boundary loop position k (0..nb-1).
struct Chords {
  std::vector<std::array<int, 2>> ends;        // chord -> its two loop positions, ascending
  std::vector<std::array<int, 2>> faces;       // chord -> the two triangles it separates
  std::vector<std::array<int, 3>> corners;     // triangle -> loop positions, counter-clockwise
  std::vector<std::array<int, 3>> side_chord;  // triangle -> chord opposite corner k (-1: rim)
};

absl::StatusOr<Chords> TriangulatePolygon(const Points& polygon) {
  TriangulateOptions options;
  options.refine = false;
  absl::StatusOr<PolygonTriangulation> cdt = CgalTriangulate(polygon, options);
  if (!cdt.ok()) return cdt.status();
  const int nb = static_cast<int>(polygon.size());
  if (static_cast<int>(cdt->vertices.size()) != nb) {
    return absl::InternalError("overlay: the polygon's triangulation added points");
  }
  Chords chords;
  std::map<std::pair<int, int>, int> id;
  for (size_t t = 0; t < cdt->triangles.size(); ++t) {
    const Triangle& tri = cdt->triangles[t];
    chords.corners.push_back({tri[0], tri[1], tri[2]});
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
        return absl::ResourceExhaustedError(
            absl::StrCat("overlay: the refinement needs more than ", max_vertices, " vertices"));
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
  const int n = static_cast<int>(shapes[0].size());
  for (const Points& s : shapes) {
    if (static_cast<int>(s.size()) != n) {
      return absl::InvalidArgumentError("overlay: shapes of different sizes");
    }
  }
  absl::StatusOr<Chords> chords = TriangulatePolygon(target_boundary);
  if (!chords.ok()) {
    return absl::Status(chords.status().code(),
                        absl::StrCat("overlay: ", chords.status().message()));
  }
  const int nb = static_cast<int>(boundary.size());
  // Loop positions on the circle: arc length of the first shape blended with even spacing (the
  // blend changes between attempts; some even share keeps every step positive).
  std::vector<double> arc(nb + 1, 0.0);
  for (int k = 0; k < nb; ++k) {
    arc[k + 1] = arc[k] + (shapes[0][boundary[(k + 1) % nb]] - shapes[0][boundary[k]]).norm();
  }
  absl::Status last = absl::FailedPreconditionError("overlay: no attempt");
  // Placements tried in turn, the first whose worst triangle is at least kGoodQuality kept, else
  // the best: the spacing (even, or partly by arc length) decides where chords pass close to
  // mesh vertices and cut thin pieces. Even spacing first: arc length crowds short boundary
  // edges, whose chords then graze the vertices between them.
  constexpr double kBlends[] = {0.0, 0.5, 0.9, 0.25, 0.75, 0.6};
  constexpr double kGoodQuality = 1e-3;
  std::optional<OverlayResult> best;
  double best_quality = 0.0;
  for (int attempt = 0; attempt < 6 && best_quality < kGoodQuality; ++attempt) {
    if (Cancelled(cancel)) return absl::CancelledError("overlay cancelled");
    // Each point also moves by a pseudo-random fraction of under a quarter of the even step
    // (symmetric drawings put mesh vertices on chords otherwise).
    const double blend = arc[nb] > 0 ? kBlends[attempt] : 0.0;
    std::uint64_t state = 0x9E3779B97F4A7C15ull * (attempt + 1);
    Points circle(nb);
    for (int k = 0; k < nb; ++k) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const double jitter = 0.2 * ((state >> 11) * 0x1.0p-53 - 0.5) * (1.0 - blend) / nb;
      const double share =
          (arc[nb] > 0 ? blend * arc[k] / arc[nb] : 0.0) + (1.0 - blend) * k / nb + jitter;
      const double angle = 2.0 * std::numbers::pi * share;
      circle[k] = Point(std::cos(angle), std::sin(angle));
    }
    if (!StrictlyConvex(circle)) {
      last = absl::FailedPreconditionError("overlay: the circle's points are not convex");
      continue;
    }
    MapToBoundaryOptions tutte;
    tutte.tutte_when_convex = true;
    tutte.polish_iterations = 0;
    absl::StatusOr<Points> disk =
        MapToBoundary(shapes[0], triangles, boundary, circle, tutte, cancel);
    if (!disk.ok()) {
      if (absl::IsCancelled(disk.status()) || absl::IsResourceExhausted(disk.status())) {
        return disk.status();
      }
      last = disk.status();
      continue;
    }
    bool embedded = true;
    for (const Triangle& t : triangles) {
      embedded &= ExactOrientation((*disk)[t[0]], (*disk)[t[1]], (*disk)[t[2]]) > 0;
    }
    if (!embedded) {
      last = absl::FailedPreconditionError("overlay: the convex embedding has a flat triangle");
      continue;
    }

    Overlay overlay(triangles, boundary, *disk, circle, *chords);
    if (absl::Status run = overlay.Run(cancel, max_vertices); !run.ok()) return run;

    OverlayResult result;
    const int total = overlay.num_vertices();
    result.added_vertices = total - n;
    result.shapes = shapes;
    for (Points& s : result.shapes) s.resize(total);
    Points target(total);
    for (int v = 0; v < n; ++v) {
      if (const int k = overlay.LoopPosition(v); k >= 0) {
        target[v] = target_boundary[k];
        continue;
      }
      const auto& corners = chords->corners[overlay.LocateVertex(v)];
      const Point& a = circle[corners[0]];
      const Point& b = circle[corners[1]];
      const Point& c = circle[corners[2]];
      const Point& p = (*disk)[v];
      const double area = Cross(b - a, c - a);
      const double lb = Cross(p - a, c - a) / area, lc = Cross(b - a, p - a) / area;
      target[v] = (1.0 - lb - lc) * target_boundary[corners[0]] + lb * target_boundary[corners[1]] +
                  lc * target_boundary[corners[2]];
    }
    for (size_t i = 0; i < overlay.crossings().size(); ++i) {
      const Crossing& x = overlay.crossings()[i];
      const int v = n + static_cast<int>(i);
      for (Points& s : result.shapes) s[v] = (1.0 - x.t) * s[x.u] + x.t * s[x.v];
      const auto& e = chords->ends[x.chord];
      target[v] = (1.0 - x.s) * target_boundary[e[0]] + x.s * target_boundary[e[1]];
    }
    result.shapes.push_back(std::move(target));

    // Fan each cell from the corner that keeps its smallest triangle largest, relative to the
    // cell, over every drawing.
    for (const Overlay::Cell& cell : overlay.cells()) {
      const int m = static_cast<int>(cell.vertices.size());
      int best = 0;
      double best_worst = -std::numeric_limits<double>::infinity();
      for (int apex = 0; apex < m && m > 3; ++apex) {
        double worst = std::numeric_limits<double>::infinity();
        for (const Points& s : result.shapes) {
          double cell_area = 0.0;
          for (int i = 1; i + 1 < m; ++i) {
            cell_area += Cross(s[cell.vertices[i]] - s[cell.vertices[0]],
                               s[cell.vertices[i + 1]] - s[cell.vertices[0]]);
          }
          const Point& o = s[cell.vertices[apex]];
          for (int i = 1; i + 1 < m; ++i) {
            const Point& p = s[cell.vertices[(apex + i) % m]];
            const Point& q = s[cell.vertices[(apex + i + 1) % m]];
            worst = std::min(worst, Cross(p - o, q - o) / std::abs(cell_area));
          }
        }
        if (worst > best_worst) best_worst = worst, best = apex;
      }
      for (int i = 1; i + 1 < m; ++i) {
        result.triangles.push_back({cell.vertices[best], cell.vertices[(best + i) % m],
                                    cell.vertices[(best + i + 1) % m]});
      }
    }
    // Crossings that cut slivers off a mesh triangle (a chord passing near one of its
    // vertices) merge into a neighbour where that leaves every drawing's thinnest triangle no
    // thinner (collapse_vertices.h); the input's vertices stay.
    {
      absl::StatusOr<CollapseResult> coarse =
          CollapseVertices(result.triangles, result.shapes, n, CollapseOptions{}, cancel);
      if (!coarse.ok()) return coarse.status();
      result.triangles = std::move(coarse->triangles);
      result.shapes = std::move(coarse->shapes);
      result.added_vertices -= coarse->removed;
    }
    // Positive in doubles, as every later stage judges a triangle (validate.h's CountInverted),
    // and how thin the thinnest is (4 sqrt(3) area / sum of squared edges: 1 equilateral).
    double worst = std::numeric_limits<double>::infinity();
    for (const Points& s : result.shapes) {
      worst = std::min(worst, CountInverted(result.triangles, s) == 0
                                  ? WorstTriangleQuality(result.triangles, s)
                                  : -1.0);
    }
    if (!(worst > 0)) {
      last = absl::FailedPreconditionError(
          "overlay: a cell is too thin for double precision in some drawing");
      continue;
    }
    if (worst > best_quality) best_quality = worst, best = std::move(result);
  }
  if (best.has_value()) return *std::move(best);
  return last;
}

}  // namespace inbetween::solver
