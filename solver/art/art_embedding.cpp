// Art in mesh coordinates (see art_embedding.h).
#include "solver/art/art_embedding.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "solver/art/triangle_grid.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

// Parameters t in (0, 1) where segment pq crosses an edge of a triangle from `candidates`,
// ascending, none within `min_gap` of 0, 1 or one another.
std::vector<double> EdgeCrossings(const Point& p, const Point& q,
                                  const std::vector<int>& candidates,
                                  const std::vector<Triangle>& triangles, const Points& x,
                                  double min_gap) {
  std::vector<double> ts;
  const Point d = q - p;
  for (int t : candidates) {
    for (int k = 0; k < 3; ++k) {
      const Point& a = x[triangles[t][k]];
      const Point e = x[triangles[t][(k + 1) % 3]] - a;
      const double denom = Cross(d, e);
      if (denom == 0.0) continue;  // parallel: the other edges at its ends give the crossings
      const double along = Cross(a - p, e) / denom;  // on pq
      const double on_edge = Cross(a - p, d) / denom;
      constexpr double kEdgeSlack = 1e-12;  // a crossing through a vertex counts on both edges
      if (along > min_gap && along < 1.0 - min_gap && on_edge >= -kEdgeSlack &&
          on_edge <= 1.0 + kEdgeSlack) {
        ts.push_back(along);
      }
    }
  }
  std::sort(ts.begin(), ts.end());
  std::vector<double> kept;
  for (double t : ts) {
    if (kept.empty() || t - kept.back() > min_gap) kept.push_back(t);
  }
  if (!kept.empty() && 1.0 - kept.back() <= min_gap) kept.pop_back();
  return kept;
}

// The boundary vertices of a shape, for splitting art segments that run along the boundary
// (on it, or a little outside: a fill whose outline is the drawing's outline, a stroke on it).
// Such a segment crosses no triangle edge there, so without a split it would ride one triangle
// and become a chord across the boundary wherever a frame bends it. It is split at the foot of
// every boundary vertex it passes within a quarter of that vertex's shorter boundary edge: the
// piece between two feet then follows the boundary edge between the two vertices.
class BoundaryFeet {
 public:
  // Boundary edges are the directed triangle edges whose reverse is no triangle's edge (the
  // sides of cuts and openings included), so no boundary loops are needed.
  BoundaryFeet(const Multimesh& mesh, const Points& x) : x_(x) {
    std::vector<std::pair<int, int>> edges;
    edges.reserve(3 * mesh.triangles.size());
    for (const Triangle& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) edges.emplace_back(t[k], t[(k + 1) % 3]);
    }
    std::sort(edges.begin(), edges.end());
    std::vector<double> reach(x.size(), std::numeric_limits<double>::infinity());
    for (const auto& [a, b] : edges) {
      if (std::binary_search(edges.begin(), edges.end(), std::make_pair(b, a))) continue;
      const double length = (x[a] - x[b]).norm();
      reach[a] = std::min(reach[a], 0.25 * length);
      reach[b] = std::min(reach[b], 0.25 * length);
    }
    for (size_t v = 0; v < x.size(); ++v) {
      if (!std::isfinite(reach[v])) continue;
      vertices_.push_back({x[v].x(), static_cast<int>(v), reach[v]});
      max_reach_ = std::max(max_reach_, reach[v]);
    }
    std::sort(vertices_.begin(), vertices_.end(), [](const Entry& a, const Entry& b) {
      return a.x < b.x || (a.x == b.x && a.vertex < b.vertex);
    });
  }

  // Parameters t in (min_gap, 1 - min_gap) on pq of the feet of boundary vertices within reach.
  void Add(const Point& p, const Point& q, double min_gap, std::vector<double>* ts) const {
    const Point d = q - p;
    const double length2 = d.squaredNorm();
    if (vertices_.empty() || !(length2 > 0.0)) return;
    const double lo = std::min(p.x(), q.x()) - max_reach_, hi = std::max(p.x(), q.x()) + max_reach_;
    auto it = std::lower_bound(vertices_.begin(), vertices_.end(), lo,
                               [](const Entry& e, double x) { return e.x < x; });
    for (; it != vertices_.end() && it->x <= hi; ++it) {
      const Point& v = x_[it->vertex];
      const double t = (v - p).dot(d) / length2;
      if (t <= min_gap || t >= 1.0 - min_gap) continue;
      if ((p + t * d - v).norm() <= it->reach) ts->push_back(t);
    }
  }

 private:
  struct Entry {
    double x;
    int vertex;
    double reach;
  };
  const Points& x_;
  std::vector<Entry> vertices_;
  double max_reach_ = 0.0;
};

class Embedder {
 public:
  Embedder(const Multimesh& mesh, int key, const ArtEmbeddingOptions& options,
           ArtEmbeddingReport* report)
      : mesh_(mesh),
        x_(mesh.shapes[key]),
        options_(options),
        grid_(mesh.triangles, x_, options.triangles_per_cell),
        feet_(mesh, x_),
        report_(report) {}

  bool empty() const { return grid_.empty(); }

  EmbeddedPath Path(const ArtPath& drawn) {
    EmbeddedPath path;
    path.closed = drawn.closed;
    const Points& p = drawn.points;
    const size_t n = p.size();
    for (size_t i = 0; i < n; ++i) {
      path.points.push_back(Embed(p[i], false));
      const bool has_segment = i + 1 < n || (drawn.closed && n >= 2);
      if (!options_.split_at_edges || !has_segment) continue;
      const Point& q = p[(i + 1) % n];
      if (p[i] == q) continue;
      std::vector<double> ts = EdgeCrossings(p[i], q, grid_.AlongSegment(p[i], q),
                                             mesh_.triangles, x_, options_.min_split_fraction);
      const size_t crossings = ts.size();
      feet_.Add(p[i], q, options_.min_split_fraction, &ts);
      if (ts.size() > crossings) {  // merge the feet in, keeping splits apart
        std::sort(ts.begin(), ts.end());
        std::vector<double> kept;
        for (double t : ts) {
          if (kept.empty() || t - kept.back() > options_.min_split_fraction) kept.push_back(t);
        }
        ts = std::move(kept);
      }
      for (double t : ts) {
        path.points.push_back(Embed(p[i] + t * (q - p[i]), true));
        ++report_->inserted;
      }
    }
    return path;
  }

 private:
  EmbeddedPoint Embed(const Point& p, bool inserted) {
    EmbeddedPoint e;
    e.inserted = inserted;
    e.triangle = grid_.Containing(p, options_.inside_tolerance);
    if (e.triangle < 0) {
      double distance = 0.0;
      e.triangle = grid_.Nearest(p, &distance);
      ++report_->outside;
      report_->max_outside = std::max(report_->max_outside, distance);
    }
    e.corners = mesh_.triangles[e.triangle];
    e.barycentric = Barycentric(x_[e.corners[0]], x_[e.corners[1]], x_[e.corners[2]], p);
    ++report_->points;
    return e;
  }

  const Multimesh& mesh_;
  const Points& x_;
  const ArtEmbeddingOptions& options_;
  TriangleGrid grid_;
  BoundaryFeet feet_;
  ArtEmbeddingReport* report_;
};

std::string LayerName(const ArtLayer& layer, size_t index) {
  std::string s = absl::StrCat("art layer ", index + 1);
  if (!layer.id.empty()) absl::StrAppend(&s, " (id \"", layer.id, "\")");
  return s;
}

}  // namespace

absl::StatusOr<EmbeddedArt> EmbedArt(const Multimesh& mesh, int key,
                                     const std::vector<ArtLayer>& art,
                                     const ArtEmbeddingOptions& options,
                                     ArtEmbeddingReport* report) {
  const auto start = std::chrono::steady_clock::now();
  if (key < 0 || key >= mesh.num_shapes()) {
    return absl::InvalidArgumentError(
        absl::StrFormat("art embedding: drawing %d is not in the multimesh (%d drawings)", key + 1,
                        mesh.num_shapes()));
  }
  const int nv = mesh.num_vertices();
  for (const Triangle& t : mesh.triangles) {
    if (const std::optional<int> v = IndexOutOfRange(t, nv)) {
      return absl::InvalidArgumentError(
          absl::StrCat("art embedding: triangle vertex ", *v, " out of range [0, ", nv, ")"));
    }
  }
  for (size_t l = 0; l < art.size(); ++l) {
    for (size_t k = 0; k < art[l].paths.size(); ++k) {
      for (size_t i = 0; i < art[l].paths[k].points.size(); ++i) {
        if (!art[l].paths[k].points[i].allFinite()) {
          return absl::InvalidArgumentError(absl::StrCat("drawing ", key + 1, ", ",
                                                         LayerName(art[l], l), ", path ", k + 1,
                                                         ": point ", i + 1, " is not finite"));
        }
      }
    }
  }
  ArtEmbeddingReport local;
  if (report == nullptr) report = &local;
  *report = {};
  Embedder embedder(mesh, key, options, report);
  if (embedder.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "art embedding: drawing %d's shape has no triangle of positive area", key + 1));
  }
  EmbeddedArt out;
  out.key = key;
  out.num_vertices = nv;
  for (const ArtLayer& layer : art) {
    EmbeddedLayer& e = out.layers.emplace_back();
    e.paint = layer;
    e.paint.paths.clear();
    for (const ArtPath& path : layer.paths) e.paths.push_back(embedder.Path(path));
  }
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

absl::StatusOr<std::vector<EmbeddedArt>> EmbedDrawingsArt(const Multimesh& mesh,
                                                          const std::vector<Drawing>& drawings,
                                                          const ArtEmbeddingOptions& options) {
  std::vector<EmbeddedArt> out;
  if (std::all_of(drawings.begin(), drawings.end(),
                  [](const Drawing& d) { return d.art.empty(); })) {
    return out;
  }
  if (mesh.num_shapes() < static_cast<int>(drawings.size())) {
    return absl::InvalidArgumentError(absl::StrCat("art of ", drawings.size(),
                                                   " drawings for a multimesh of ",
                                                   mesh.num_shapes(), " shapes"));
  }
  out.reserve(drawings.size());
  for (size_t k = 0; k < drawings.size(); ++k) {
    absl::StatusOr<EmbeddedArt> art =
        EmbedArt(mesh, static_cast<int>(k), drawings[k].art, options);
    if (!art.ok()) {
      return absl::Status(art.status().code(),
                          absl::StrCat("drawing ", k + 1, ": ", art.status().message()));
    }
    out.push_back(*std::move(art));
  }
  return out;
}

Points PlacePath(const EmbeddedPath& path, const Points& vertices) {
  Points out;
  out.reserve(path.points.size());
  for (const EmbeddedPoint& e : path.points) {
    const Eigen::Vector3d& b = e.barycentric;
    out.push_back(b[0] * vertices[e.corners[0]] + b[1] * vertices[e.corners[1]] +
                  b[2] * vertices[e.corners[2]]);
  }
  return out;
}

absl::StatusOr<std::vector<ArtLayer>> PlaceArt(const EmbeddedArt& art, const Points& vertices) {
  if (static_cast<int>(vertices.size()) != art.num_vertices) {
    return absl::InvalidArgumentError(
        absl::StrFormat("art of drawing %d is embedded in a mesh of %d vertices, not %d",
                        art.key + 1, art.num_vertices, vertices.size()));
  }
  std::vector<ArtLayer> out;
  out.reserve(art.layers.size());
  for (const EmbeddedLayer& layer : art.layers) {
    ArtLayer& placed = out.emplace_back(layer.paint);
    for (const EmbeddedPath& path : layer.paths) {
      placed.paths.push_back({PlacePath(path, vertices), path.closed});
    }
  }
  return out;
}

}  // namespace inbetween::solver
