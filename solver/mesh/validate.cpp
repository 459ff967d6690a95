// Validators for meshes and multimeshes: orientation of every triangle in every shape.
#include "solver/mesh/validate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/cgal_predicates.h"

namespace inbetween::solver {

int CountInverted(const std::vector<Triangle>& triangles, const Points& x, double min_area2) {
  int count = 0;
  for (const Triangle& t : triangles) {
    const double a = SignedArea2(t, x);
    if (!(a > min_area2)) ++count;  // NaN counts as inverted
  }
  return count;
}

double TriangleQuality(const Point& a, const Point& b, const Point& c) {
  const double area2 = SignedArea2(a, b, c);
  const double edges = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return edges > 0.0 ? 2.0 * std::sqrt(3.0) * area2 / edges : 0.0;
}

double WorstTriangleQuality(const std::vector<Triangle>& triangles, const Points& x, int* where) {
  double worst = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < triangles.size(); ++k) {
    const Triangle& t = triangles[k];
    const double q = TriangleQuality(x[t[0]], x[t[1]], x[t[2]]);
    if (q < worst) {
      worst = q;
      if (where != nullptr) *where = static_cast<int>(k);
    }
  }
  return worst;
}

namespace {

// No two of the boundary `edges` (directed, in (from, to) order) cross properly in geometry x.
absl::Status BoundaryEdgesDoNotCross(const std::vector<std::pair<int, int>>& edges,
                                     const Points& x) {
  if (edges.size() < 4) return absl::OkStatus();
  Point lo = x[edges[0].first], hi = lo;
  double total = 0.0;
  for (const auto& [a, b] : edges) {
    lo = lo.cwiseMin(x[a]).cwiseMin(x[b]), hi = hi.cwiseMax(x[a]).cwiseMax(x[b]);
    total += (x[b] - x[a]).norm();
  }
  // Cells about as wide as an average edge, at most 2048 a side.
  const double cell = std::max(total / edges.size(), 1e-12 * std::max(1.0, (hi - lo).norm()));
  const int nx = std::clamp(static_cast<int>((hi.x() - lo.x()) / cell) + 1, 1, 2048);
  const int ny = std::clamp(static_cast<int>((hi.y() - lo.y()) / cell) + 1, 1, 2048);
  const double cx = (hi.x() - lo.x()) / nx + 1e-300, cy = (hi.y() - lo.y()) / ny + 1e-300;
  auto cell_of = [&](double v, double origin, double size, int count) {
    return std::clamp(static_cast<int>((v - origin) / size), 0, count - 1);
  };
  std::vector<std::vector<int>> grid(static_cast<size_t>(nx) * ny);
  for (size_t e = 0; e < edges.size(); ++e) {
    const Point& p = x[edges[e].first];
    const Point& q = x[edges[e].second];
    const int x0 = cell_of(std::min(p.x(), q.x()), lo.x(), cx, nx);
    const int x1 = cell_of(std::max(p.x(), q.x()), lo.x(), cx, nx);
    const int y0 = cell_of(std::min(p.y(), q.y()), lo.y(), cy, ny);
    const int y1 = cell_of(std::max(p.y(), q.y()), lo.y(), cy, ny);
    for (int i = x0; i <= x1; ++i) {
      for (int j = y0; j <= y1; ++j)
        grid[static_cast<size_t>(j) * nx + i].push_back(static_cast<int>(e));
    }
  }
  for (const std::vector<int>& bucket : grid) {
    for (size_t i = 0; i < bucket.size(); ++i) {
      for (size_t j = i + 1; j < bucket.size(); ++j) {
        const auto [a, b] = edges[bucket[i]];
        const auto [c, d] = edges[bucket[j]];
        if (a == c || a == d || b == c || b == d) continue;
        const int o1 = ExactOrientation(x[a], x[b], x[c]), o2 = ExactOrientation(x[a], x[b], x[d]);
        if (o1 * o2 >= 0) continue;
        const int o3 = ExactOrientation(x[c], x[d], x[a]), o4 = ExactOrientation(x[c], x[d], x[b]);
        if (o3 * o4 >= 0) continue;
        const Point at = 0.25 * (x[a] + x[b] + x[c] + x[d]);
        return absl::InvalidArgumentError(absl::StrCat("boundary edges ", a, "-", b, " and ", c,
                                                       "-", d, " cross near (", at.x(), ", ",
                                                       at.y(), ")"));
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ValidateBoundaryDoesNotCross(const std::vector<Triangle>& triangles, const Points& x) {
  std::set<std::pair<int, int>> directed;
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) directed.insert({t[k], t[(k + 1) % 3]});
  }
  std::vector<std::pair<int, int>> edges;
  for (const auto& [a, b] : directed) {
    if (!directed.count({b, a})) edges.push_back({a, b});
  }
  return BoundaryEdgesDoNotCross(edges, x);
}

namespace {

// Multimesh::art: none, or one per shape, key k in shape k, every point in a triangle of the
// mesh with its corners and finite barycentric coordinates.
absl::Status ValidateArt(const Multimesh& mesh) {
  if (mesh.art.empty()) return absl::OkStatus();
  if (static_cast<int>(mesh.art.size()) != mesh.num_shapes()) {
    return absl::InvalidArgumentError(absl::StrCat("multimesh art: ", mesh.art.size(),
                                                   " drawings for ", mesh.num_shapes(), " shapes"));
  }
  for (size_t k = 0; k < mesh.art.size(); ++k) {
    const EmbeddedArt& art = mesh.art[k];
    if (art.key != static_cast<int>(k) || art.num_vertices != mesh.num_vertices()) {
      return absl::InvalidArgumentError(
          absl::StrCat("multimesh art ", k, ": key ", art.key, " for ", art.num_vertices,
                       " vertices, expected key ", k, " for ", mesh.num_vertices()));
    }
    for (size_t l = 0; l < art.layers.size(); ++l) {
      for (size_t p = 0; p < art.layers[l].paths.size(); ++p) {
        for (const EmbeddedPoint& e : art.layers[l].paths[p].points) {
          if (e.triangle < 0 || e.triangle >= static_cast<int>(mesh.triangles.size()) ||
              e.corners != mesh.triangles[e.triangle] || !e.barycentric.allFinite()) {
            return absl::InvalidArgumentError(
                absl::StrCat("multimesh art ", k, " layer ", l, " path ", p,
                             ": a point in triangle ", e.triangle, " of ", mesh.triangles.size(),
                             " with other corners or non-finite coordinates"));
          }
        }
      }
    }
  }
  return absl::OkStatus();
}

// Every shape has the vertex count of shape 0 and finite positions; every triangle, boundary and
// pinned index is in range (pinned ascending and distinct).
absl::Status ValidateIndices(const Multimesh& mesh) {
  const int n = mesh.num_vertices();
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    if (static_cast<int>(mesh.shapes[s].size()) != n) {
      return absl::InvalidArgumentError(absl::StrCat(
          "multimesh shape ", s, " has ", mesh.shapes[s].size(), " vertices, shape 0 has ", n));
    }
    for (int v = 0; v < n; ++v) {
      if (!mesh.shapes[s][v].allFinite()) {
        return absl::InvalidArgumentError(
            absl::StrCat("multimesh shape ", s, " vertex ", v, " is not finite"));
      }
    }
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    if (const std::optional<int> v = IndexOutOfRange(tri, n)) {
      return absl::InvalidArgumentError(absl::StrCat("multimesh triangle ", t, " has vertex index ",
                                                     *v, " out of range [0, ", n, ")"));
    }
    if (RepeatsVertex(tri)) {
      return absl::InvalidArgumentError(
          absl::StrCat("multimesh triangle ", t, " repeats a vertex"));
    }
  }
  for (int v : mesh.boundary) {
    if (v < 0 || v >= n) {
      return absl::InvalidArgumentError(
          absl::StrCat("multimesh boundary vertex ", v, " out of range [0, ", n, ")"));
    }
  }
  for (size_t i = 0; i < mesh.pinned.size(); ++i) {
    const int v = mesh.pinned[i];
    if (v < 0 || v >= n) {
      return absl::InvalidArgumentError(
          absl::StrCat("multimesh pinned vertex ", v, " out of range [0, ", n, ")"));
    }
    if (i > 0 && !(mesh.pinned[i - 1] < v)) {
      return absl::InvalidArgumentError(
          absl::StrCat("multimesh pinned vertices are not ascending and distinct at ", v));
    }
  }
  return absl::OkStatus();
}

// Shared topology: one consistently oriented manifold, so each directed edge belongs to one
// triangle (a repeated or overlapping triangle or a non-manifold edge uses one twice). The
// directed edges {from, to, triangle}, sorted, go to `directed`.
absl::Status ValidateManifold(const Multimesh& mesh, std::vector<std::array<int, 3>>* directed) {
  directed->reserve(3 * mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      directed->push_back({tri[k], tri[(k + 1) % 3], static_cast<int>(t)});
    }
  }
  std::sort(directed->begin(), directed->end());
  const std::vector<std::array<int, 3>>& d = *directed;
  for (size_t i = 1; i < d.size(); ++i) {
    if (d[i][0] == d[i - 1][0] && d[i][1] == d[i - 1][1]) {
      return absl::InvalidArgumentError(absl::StrCat("multimesh triangles ", d[i - 1][2], " and ",
                                                     d[i][2], " both have edge ", d[i][0], "-",
                                                     d[i][1], " (overlapping or non-manifold)"));
    }
  }
  return absl::OkStatus();
}

// Boundary vertices on the boundary: each on an edge with a triangle on one side only. The
// boundary edges, in (from, to) order, go to `boundary_edges` for the crossing check.
absl::Status ValidateBoundary(const Multimesh& mesh,
                              const std::vector<std::array<int, 3>>& directed,
                              std::vector<std::pair<int, int>>* boundary_edges) {
  std::vector<bool> on_boundary(mesh.num_vertices(), false);
  for (const auto& [a, b, t] : directed) {
    const std::array<int, 3> reverse = {b, a, -1};
    auto it = std::lower_bound(directed.begin(), directed.end(), reverse);
    if (it == directed.end() || (*it)[0] != b || (*it)[1] != a) {
      on_boundary[a] = on_boundary[b] = true;
      boundary_edges->push_back({a, b});
    }
  }
  for (size_t k = 0; k < mesh.boundary.size(); ++k) {
    if (!on_boundary[mesh.boundary[k]]) {
      return absl::InvalidArgumentError(absl::StrCat("multimesh boundary vertex ", mesh.boundary[k],
                                                     " (boundary[", k,
                                                     "]) is not on the boundary"));
    }
  }
  if (absl::Status s = ValidateBoundaryLoops(mesh); !s.ok()) return s;
  if (!mesh.boundary_loops.empty()) {
    std::vector<int> concatenation;
    for (const std::vector<int>& loop : mesh.boundary_loops) {
      concatenation.insert(concatenation.end(), loop.begin(), loop.end());
    }
    if (concatenation != mesh.boundary) {
      return absl::InvalidArgumentError("multimesh boundary is not the concatenation of its loops");
    }
  }
  return absl::OkStatus();
}

// In every shape every triangle is positively oriented and no two boundary edges cross.
absl::Status ValidateEmbedding(const Multimesh& mesh,
                               const std::vector<std::pair<int, int>>& boundary_edges) {
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const double a = SignedArea2(mesh.triangles[t], mesh.shapes[s]);
      if (!(a > 0)) {
        return absl::InvalidArgumentError(absl::StrCat("multimesh shape ", s, " triangle ", t,
                                                       a == 0 ? " is degenerate" : " is inverted",
                                                       " (signed area ", 0.5 * a, ")"));
      }
    }
    if (absl::Status crossing = BoundaryEdgesDoNotCross(boundary_edges, mesh.shapes[s]);
        !crossing.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("multimesh shape ", s, ": ", crossing.message()));
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ValidateMultimesh(const Multimesh& mesh) {
  if (mesh.shapes.empty()) return absl::InvalidArgumentError("multimesh has no shapes");
  if (absl::Status s = ValidateIndices(mesh); !s.ok()) return s;
  std::vector<std::array<int, 3>> directed;
  if (absl::Status s = ValidateManifold(mesh, &directed); !s.ok()) return s;
  std::vector<std::pair<int, int>> boundary_edges;
  if (absl::Status s = ValidateBoundary(mesh, directed, &boundary_edges); !s.ok()) return s;
  if (absl::Status s = ValidateCohesiveEdges(mesh); !s.ok()) return s;
  if (absl::Status s = ValidateEmbedding(mesh, boundary_edges); !s.ok()) return s;
  return ValidateArt(mesh);
}

absl::Status ValidateBoundaryLoops(const Multimesh& mesh) {
  if (mesh.boundary_loops.empty()) return absl::OkStatus();
  const int n = mesh.num_vertices();
  std::set<std::pair<int, int>> directed;
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) directed.insert({t[k], t[(k + 1) % 3]});
  }
  size_t on_loops = 0;
  std::set<std::pair<int, int>> listed;
  for (size_t l = 0; l < mesh.boundary_loops.size(); ++l) {
    const std::vector<int>& loop = mesh.boundary_loops[l];
    on_loops += loop.size();
    for (size_t k = 0; k < loop.size(); ++k) {
      const int a = loop[k], b = loop[(k + 1) % loop.size()];
      if (a < 0 || a >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("multimesh boundary loop ", l, " vertex ", a, " out of range"));
      }
      // A boundary edge has the mesh on its left and nothing on its right.
      if (!directed.count({a, b}) || directed.count({b, a})) {
        return absl::InvalidArgumentError(absl::StrCat("multimesh boundary loop ", l, ": edge ", a,
                                                       "-", b, " is not a boundary edge"));
      }
      if (!listed.insert({a, b}).second) {
        return absl::InvalidArgumentError(
            absl::StrCat("multimesh boundary loop ", l, ": edge ", a, "-", b, " is listed twice"));
      }
    }
  }
  size_t boundary_edges = 0;
  for (const auto& [a, b] : directed) boundary_edges += directed.count({b, a}) ? 0 : 1;
  if (boundary_edges != on_loops) {
    return absl::InvalidArgumentError(absl::StrCat(
        "multimesh has ", boundary_edges, " boundary edges but its loops list ", on_loops));
  }
  return absl::OkStatus();
}

absl::Status ValidateCohesiveEdges(const Multimesh& mesh, double relative_tolerance) {
  const int n = mesh.num_vertices();
  for (size_t c = 0; c < mesh.cohesive_edges.size(); ++c) {
    for (int v : mesh.cohesive_edges[c]) {
      if (v < 0 || v >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("multimesh cohesive edge ", c, " vertex ", v, " out of range"));
      }
    }
  }
  if (mesh.cohesive_closed.empty()) return absl::OkStatus();
  if (mesh.cohesive_closed.size() != mesh.shapes.size()) {
    return absl::InvalidArgumentError("multimesh cohesive_closed needs one list per shape");
  }
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    const Points& x = mesh.shapes[s];
    if (x.empty()) continue;
    Point lo = x[0], hi = x[0];
    for (const Point& p : x) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double tolerance = relative_tolerance * (hi - lo).norm();
    for (int c : mesh.cohesive_closed[s]) {
      if (c < 0 || c >= static_cast<int>(mesh.cohesive_edges.size())) {
        return absl::InvalidArgumentError(
            absl::StrCat("multimesh shape ", s, " lists cohesive edge ", c, " out of range"));
      }
      const auto& [a, b, cc, d] = mesh.cohesive_edges[c];
      // Written so that a NaN distance (non-finite coordinates) is not collocated either.
      if (!((x[a] - x[cc]).norm() <= tolerance && (x[b] - x[d]).norm() <= tolerance)) {
        return absl::InvalidArgumentError(absl::StrCat(
            "multimesh shape ", s, ": cohesive edge ", c, " is closed there but its sides are ",
            std::max((x[a] - x[cc]).norm(), (x[b] - x[d]).norm()), " apart"));
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace inbetween::solver
