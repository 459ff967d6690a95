// Stage driver: drawings -> compatible multimesh (S-Sec.1, S-Fig.2). Directed graph flow per
// drawing (S-Alg.1), equivalence check, boundary correspondence, CGAL mesh of drawing 1 cut open
// along its cuts/openings, boundary Steiner points mirrored so every cohesive edge pairs up in
// every drawing, then an injective map of each connected component into every other drawing.
#include "solver/mesh/build_multimesh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numeric>
#include <optional>
#include <string>

#include "absl/strings/str_cat.h"
#include "solver/art/art_embedding.h"
#include "solver/core/error_reason.h"
#include "solver/geometry/boundary_correspondence.h"
#include "solver/geometry/graph_flow.h"
#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/map_to_boundary.h"
#include "solver/mesh/overlay_mesh.h"
#include "solver/mesh/refine_boundary_fans.h"
#include "solver/mesh/split_boundary_chords.h"
#include "solver/mesh/validate.h"
#include "solver/mesh/vertex_order.h"

namespace inbetween::solver {
namespace {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int Find(int x) { return parent[x] == x ? x : parent[x] = Find(parent[x]); }
  void Unite(int a, int b) { parent[Find(a)] = Find(b); }
};

// One boundary vertex of the mesh: on correspondence edge `edge` at parameter t in [0, 1).
struct BoundaryEntry {
  int vertex;
  int edge;
  double t;
};

// Drawing 1's mesh with the boundary known edge by edge.
struct CutMesh {
  Points vertices;
  std::vector<Triangle> triangles;
  // entries[e]: the vertices on correspondence edge e from its start (t = 0) onwards.
  std::vector<std::vector<BoundaryEntry>> entries;
};

// Duplicates every vertex along the cut/opening sides (one copy per fan of triangles between
// constrained edges) and lists the boundary vertices of each correspondence edge.
absl::StatusOr<CutMesh> CutAlongSeams(const DomainTriangulation& dt,
                                      const BoundaryCorrespondence& bc) {
  const int num_tri = static_cast<int>(dt.triangles.size());
  using Edge = std::pair<int, int>;
  std::map<Edge, bool> constrained;
  auto chain_of = [&](int g, int k) {
    std::vector<int> c = {dt.loop_vertex[g][k]};
    c.insert(c.end(), dt.edge_chain[g][k].begin(), dt.edge_chain[g][k].end());
    c.push_back(dt.loop_vertex[g][(k + 1) % dt.loop_vertex[g].size()]);
    return c;
  };
  for (size_t g = 0; g < dt.loop_vertex.size(); ++g) {
    for (size_t k = 0; k < dt.loop_vertex[g].size(); ++k) {
      const std::vector<int> c = chain_of(g, k);
      for (size_t j = 0; j + 1 < c.size(); ++j) constrained[std::minmax(c[j], c[j + 1])] = true;
    }
  }
  std::map<Edge, std::pair<int, int>> directed;  // (a, b) -> (triangle, corner of a)
  for (int t = 0; t < num_tri; ++t) {
    for (int k = 0; k < 3; ++k)
      directed[{dt.triangles[t][k], dt.triangles[t][(k + 1) % 3]}] = {t, k};
  }
  UnionFind corners(3 * num_tri);
  for (const auto& [e, tk] : directed) {
    if (e.first > e.second || constrained.count(std::minmax(e.first, e.second))) continue;
    auto other = directed.find({e.second, e.first});
    if (other == directed.end()) continue;
    const auto [t1, k1] = tk;
    const auto [t2, k2] = other->second;
    // a = e.first is corner k1 of t1 and corner (k2 + 1) % 3 of t2; b likewise.
    corners.Unite(3 * t1 + k1, 3 * t2 + (k2 + 1) % 3);
    corners.Unite(3 * t1 + (k1 + 1) % 3, 3 * t2 + k2);
  }
  CutMesh out;
  std::vector<int> copy(3 * num_tri, -1);
  out.triangles.resize(num_tri);
  for (int t = 0; t < num_tri; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int root = corners.Find(3 * t + k);
      if (copy[root] < 0) {
        copy[root] = static_cast<int>(out.vertices.size());
        out.vertices.push_back(dt.vertices[dt.triangles[t][k]]);
      }
      out.triangles[t][k] = copy[root];
    }
  }
  out.entries.resize(bc.num_vertices());
  for (int g = 0; g < bc.num_loops(); ++g) {
    for (size_t k = 0; k < dt.loop_vertex[g].size(); ++k) {
      const std::vector<int> c = chain_of(g, k);
      const int e = bc.loop_start[g] + static_cast<int>(k);
      const Point a = dt.vertices[c.front()], d = dt.vertices[c.back()] - a;
      for (size_t j = 0; j + 1 < c.size(); ++j) {
        const auto found = directed.find({c[j], c[j + 1]});
        if (found == directed.end()) {
          // The triangulation's inside is not on the boundary's inside here (nested loops the
          // even-odd domain and the loop orientation disagree on, typically tiny loops).
          const Point& p = dt.vertices[c[j]];
          return absl::InvalidArgumentError(
              absl::StrCat("triangulate: the mesh does not lie inside boundary loop ", g + 1,
                           " near (", p.x(), ", ", p.y(),
                           ") (loops too small or too close for the boundary vertices: try more "
                           "boundary vertices, meshing.boundary_vertices)"));
        }
        const auto [t, corner] = found->second;
        const double param = j == 0 ? 0.0 : (dt.vertices[c[j]] - a).dot(d) / d.squaredNorm();
        out.entries[e].push_back({copy[corners.Find(3 * t + corner)], e, param});
      }
    }
  }
  return out;
}

// Inserts a boundary vertex on correspondence edge e at parameter t (drawing 1's geometry),
// splitting the triangle on the drawing side of the boundary sub-edge it falls on.
void SplitBoundaryEdge(CutMesh* mesh, const std::vector<int>& next_edge_start, int e, double t) {
  std::vector<BoundaryEntry>& list = mesh->entries[e];
  size_t j = 0;
  while (j + 1 < list.size() && list[j + 1].t < t) ++j;
  const int a = list[j].vertex;
  const int b =
      j + 1 < list.size() ? list[j + 1].vertex : mesh->entries[next_edge_start[e]][0].vertex;
  const Point pa = mesh->vertices[list[0].vertex];
  const Point pb = mesh->vertices[mesh->entries[next_edge_start[e]][0].vertex];
  const int m = static_cast<int>(mesh->vertices.size());
  mesh->vertices.push_back((1 - t) * pa + t * pb);
  for (size_t i = 0; i < mesh->triangles.size(); ++i) {
    Triangle& tri = mesh->triangles[i];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] == a && tri[(k + 1) % 3] == b) {
        const int c = tri[(k + 2) % 3];
        tri = {a, m, c};
        mesh->triangles.push_back({m, b, c});
        list.insert(list.begin() + j + 1, {m, e, t});
        return;
      }
    }
  }
}

// Drawing::marks -> MultimeshOptions::marks layout (marks[m][d]), ordered by mark id. A mark id
// must appear once in every drawing or in none.
absl::StatusOr<std::vector<std::vector<Point>>> MarksFromDrawings(
    const std::vector<Drawing>& drawings) {
  std::map<int, std::vector<std::optional<Point>>> by_id;
  const int n = static_cast<int>(drawings.size());
  for (int d = 0; d < n; ++d) {
    for (const CorrespondenceMark& mark : drawings[d].marks) {
      auto& points = by_id[mark.id];
      points.resize(n);
      if (points[d]) {
        return absl::InvalidArgumentError(
            absl::StrCat("drawing ", d + 1, ": correspondence mark ", mark.id, " appears twice"));
      }
      points[d] = mark.point;
    }
  }
  std::vector<std::vector<Point>> marks;
  for (const auto& [id, points] : by_id) {
    std::vector<Point> mark;
    for (int d = 0; d < n; ++d) {
      if (!points[d]) {
        const int has = static_cast<int>(std::find_if(points.begin(), points.end(),
                                                      [](const auto& p) { return p.has_value(); }) -
                                         points.begin());
        return absl::InvalidArgumentError(absl::StrCat(
            "correspondence mark ", id, " is in drawing ", has + 1, " but not in drawing ", d + 1));
      }
      mark.push_back(*points[d]);
    }
    marks.push_back(std::move(mark));
  }
  return marks;
}

// One connected component of the mesh under construction, numbered locally, and where its
// boundary lies in the drawing being mapped.
struct Component {
  std::vector<int> global;          // local vertex -> mesh vertex
  std::vector<Triangle> triangles;  // over local vertices
  std::vector<int> boundary;        // its boundary loops, concatenated (local vertices)
  Points target_boundary;           // boundary[k]'s place in the drawing being mapped
  int num_loops = 0;
  std::vector<int> loop_sizes;  // how many of `boundary` each loop has, in order
};

Component ExtractComponent(const Multimesh& mesh, const std::vector<int>& component_of, int root,
                           const std::vector<int>& loops, const Points& target) {
  Component c;
  std::vector<int> local(component_of.size(), -1);
  for (const Triangle& t : mesh.triangles) {
    if (component_of[t[0]] != root) continue;
    Triangle lt;
    for (int k = 0; k < 3; ++k) {
      if (local[t[k]] < 0)
        local[t[k]] = static_cast<int>(c.global.size()), c.global.push_back(t[k]);
      lt[k] = local[t[k]];
    }
    c.triangles.push_back(lt);
  }
  for (int g : loops) {
    for (int v : mesh.boundary_loops[g]) {
      c.boundary.push_back(local[v]);
      c.target_boundary.push_back(target[v]);
    }
    c.loop_sizes.push_back(static_cast<int>(mesh.boundary_loops[g].size()));
  }
  c.num_loops = static_cast<int>(loops.size());
  return c;
}

// The component's vertices in one shape of the mesh.
Points Restrict(const Points& shape, const std::vector<int>& global) {
  Points out;
  out.reserve(global.size());
  for (int v : global) out.push_back(shape[v]);
  return out;
}

MapToBoundaryOptions MapOptions(const Component& c, const MultimeshOptions& options) {
  MapToBoundaryOptions map_options;
  map_options.tutte_when_convex = c.num_loops == 1;
  map_options.max_iterations = options.max_map_iterations;
  return map_options;
}

// The same, pulling from a placement `start` (no Tutte start).
MapToBoundaryOptions MapOptionsFrom(const Component& c, const MultimeshOptions& options,
                                    const Points* start) {
  MapToBoundaryOptions map_options = MapOptions(c, options);
  map_options.tutte_when_convex = map_options.tutte_first_always = false;
  map_options.start = start;
  return map_options;
}

// The drawings other than ref and d that have been placed already, in key order.
std::vector<int> PlacedOthers(const Multimesh& mesh, int ref, int d) {
  std::vector<int> placed;
  for (int e = 0; e < static_cast<int>(mesh.shapes.size()); ++e) {
    if (e != ref && e != d && !mesh.shapes[e].empty()) placed.push_back(e);
  }
  return placed;
}

// Every triangle positive does not make a map injective: the boundary may fold over itself
// (seen on a real icon's cusp). Such a map counts as not found.
absl::StatusOr<Points> Injective(const std::vector<Triangle>& triangles, absl::StatusOr<Points> m) {
  if (!m.ok()) return m;
  if (absl::Status s = ValidateBoundaryDoesNotCross(triangles, *m); !s.ok()) {
    return absl::FailedPreconditionError(
        absl::StrCat("the map folds the boundary over itself: ", s.message()));
  }
  return m;
}

// Out of memory is not a map that was not found: neither retried nor reworded as one.
bool FinalError(const absl::Status& s) {
  return absl::IsCancelled(s) || absl::IsResourceExhausted(s);
}

// Maps component c of the reference drawing's mesh into drawing d: pulled onto d's boundary
// directly, else from the maps into drawings already placed. With the overlay to fall back on
// (options.overlay), a map with a nearly flat triangle counts as not found and is handed back in
// *flat_map instead.
absl::StatusOr<Points> MapComponent(const Component& c, const Multimesh& mesh, int ref, int d,
                                    const MultimeshOptions& options, const CancelToken* cancel,
                                    std::optional<Points>* flat_map) {
  const Points source = Restrict(mesh.shapes[ref], c.global);
  const MapToBoundaryOptions map_options = MapOptions(c, options);
  absl::StatusOr<Points> mapped = Injective(
      c.triangles,
      MapToBoundary(source, c.triangles, c.boundary, c.target_boundary, map_options, cancel));
  // A pose far from the reference drawing may not be reachable by pulling the reference's
  // boundary directly; start instead from the map into an already mapped drawing, nearest in key
  // order first (neighbouring keys are usually similar poses).
  std::vector<int> mapped_before = PlacedOthers(mesh, ref, d);
  std::stable_sort(mapped_before.begin(), mapped_before.end(),
                   [d](int a, int b) { return std::abs(a - d) < std::abs(b - d); });
  for (size_t k = 0;
       k < mapped_before.size() && k < 3 && !mapped.ok() && !FinalError(mapped.status()); ++k) {
    const Points start = Restrict(mesh.shapes[mapped_before[k]], c.global);
    const MapToBoundaryOptions chained = MapOptionsFrom(c, options, &start);
    absl::StatusOr<Points> retry = Injective(
        c.triangles,
        MapToBoundary(source, c.triangles, c.boundary, c.target_boundary, chained, cancel));
    if (retry.ok() || FinalError(retry.status())) mapped = std::move(retry);
  }
  // A map with a nearly flat triangle (the pull can end with one: quality down to 1e-16 on
  // random star-shaped pairs) is no better than none while the overlay may still build.
  if (mapped.ok() && options.overlay) {
    int where = -1;
    const double worst = WorstTriangleQuality(c.triangles, *mapped, &where);
    if (worst < options.min_map_quality) {
      const Point at = (*mapped)[c.triangles[where][0]];
      *flat_map = *std::move(mapped);
      return absl::FailedPreconditionError(
          absl::StrCat("the map leaves a triangle nearly flat (quality ", worst, " near (", at.x(),
                       ", ", at.y(), "))"));
    }
  }
  return mapped;
}

// The mesh under construction, as the overlay extends it.
struct Growing {
  Multimesh* mesh;                 // triangles, and the shapes placed so far
  std::vector<int>* component_of;  // per mesh vertex
  Points* reference_points;        // the reference drawing's points (targets read them)
  int* num_vertices;
};

// Last resort for component c: a common refinement of it and a triangulation of drawing d
// (overlay_mesh.h; a component with holes is cut open into a disk for it and glued back), which
// adds vertices to the component in every drawing placed so far; c is renumbered to match.
// Returns the map into d.
absl::StatusOr<Points> OverlayComponent(Component* c, int root, int ref, int d,
                                        const MultimeshOptions& options, const Growing& g,
                                        const CancelToken* cancel) {
  Multimesh& mesh = *g.mesh;
  std::vector<int> known = {ref};  // drawings placed so far: the Tutte weights from ref
  for (int e : PlacedOthers(mesh, ref, d)) known.push_back(e);
  std::vector<Points> placed;
  for (int e : known) placed.push_back(Restrict(mesh.shapes[e], c->global));
  // The refinement counts against the mesh's vertex bound (the other components' too).
  const int budget = options.max_mesh_vertices > 0
                         ? std::max(1, options.max_mesh_vertices -
                                           (*g.num_vertices - static_cast<int>(c->global.size())))
                         : 0;
  std::vector<std::vector<int>> loops;
  std::vector<Points> target_loops;
  for (size_t l = 0, at = 0; l < c->loop_sizes.size(); at += c->loop_sizes[l++]) {
    const auto first = static_cast<std::ptrdiff_t>(at), last = first + c->loop_sizes[l];
    loops.emplace_back(c->boundary.begin() + first, c->boundary.begin() + last);
    target_loops.emplace_back(c->target_boundary.begin() + first,
                              c->target_boundary.begin() + last);
  }
  absl::StatusOr<OverlayResult> over =
      OverlayOntoDomain(c->triangles, placed, loops, target_loops, cancel, budget);
  if (!over.ok()) {
    if (absl::IsCancelled(over.status())) return over.status();
    return absl::FailedPreconditionError(over.status().message());
  }
  // New vertices get mesh indices after the existing ones, in every placed drawing and among the
  // reference's points.
  const size_t local_before = c->global.size();
  for (int i = 0; i < over->added_vertices; ++i) {
    c->global.push_back((*g.num_vertices)++);
    g.component_of->push_back(root);
    g.reference_points->push_back(over->shapes[0][c->global.size() - 1]);
  }
  for (size_t k = 0; k < known.size(); ++k) {
    Points& s = mesh.shapes[known[k]];
    for (size_t i = local_before; i < c->global.size(); ++i) s.push_back(over->shapes[k][i]);
  }
  std::vector<Triangle> kept;
  for (const Triangle& t : mesh.triangles) {
    if ((*g.component_of)[t[0]] != root) kept.push_back(t);
  }
  for (const Triangle& t : over->triangles) {
    kept.push_back({c->global[t[0]], c->global[t[1]], c->global[t[2]]});
  }
  mesh.triangles = std::move(kept);
  c->triangles = over->triangles;
  // Polish the map into drawing d from the overlay's placement (boundary already there).
  const MapToBoundaryOptions polish = MapOptionsFrom(*c, options, &over->shapes.back());
  absl::StatusOr<Points> polished =
      MapToBoundary(Restrict(mesh.shapes[ref], c->global), c->triangles, c->boundary,
                    c->target_boundary, polish, cancel);
  if (!polished.ok() && absl::IsCancelled(polished.status())) return polished.status();
  return Injective(c->triangles, polished.ok() ? std::move(polished)
                                               : absl::StatusOr<Points>(over->shapes.back()));
}

// Drawings whose mesh BuildMultimesh tries to map into the others (see ReferenceOrder).
constexpr int kMaxReferences = 3;

// The component maps one attempt made, (drawing, component) -> MapComponent's answer. The
// overlay attempt meshes the same drawing with the same correspondence as the first attempt, so
// until it first overlays, every map it asks for is one the first attempt already made (the
// construction is deterministic): it replays them instead of pulling again.
struct MapMemo {
  struct Entry {
    absl::StatusOr<Points> mapped;
    std::optional<Points> flat_map;
  };
  std::map<std::pair<int, int>, Entry> entries;
};

// How one attempt of BuildMultimesh differs from the others.
struct AttemptMode {
  bool match_corners = false;  // the correspondence matches corners to corners
  bool require_match = false;  // ABORTED (no answer) unless some loop's corners matched
  bool overlay = false;        // overlay the mesh where a component cannot be mapped
};

// One attempt's parameters besides the drawings and the caller's options.
struct AttemptOptions {
  AttemptMode mode;
  // Which drawing is meshed, in ReferenceOrder (0: the preferred one).
  int rank = 0;
  // Without overlay the attempt records its component maps here, with overlay it replays them.
  MapMemo* memo = nullptr;
  const CancelToken* cancel = nullptr;
  ProgressFn progress = nullptr;
};

// Progress for the caller, when it asked for it.
void Notify(const ProgressFn& progress, const std::string& stage, double fraction,
            const std::string& detail) {
  if (progress) progress(stage, fraction, detail);
}

// At least two drawings, every outline point finite: what the stages below assume.
absl::Status CheckDrawings(const std::vector<Drawing>& drawings) {
  const int num_shapes = static_cast<int>(drawings.size());
  if (num_shapes < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("a multimesh needs at least 2 drawings, got ", num_shapes));
  }
  for (int d = 0; d < num_shapes; ++d) {
    const auto& outlines = drawings[d].outlines;
    for (size_t o = 0; o < outlines.size(); ++o) {
      for (size_t p = 0; p < outlines[o].points.size(); ++p) {
        if (!outlines[o].points[p].allFinite()) {
          return absl::InvalidArgumentError(absl::StrCat("drawing ", d + 1, ", outline ", o + 1,
                                                         ", point ", p + 1, " is not finite"));
        }
      }
    }
  }
  return absl::OkStatus();
}

// S-Alg.1 boundaries of every drawing, which must all be of one equivalence class.
absl::StatusOr<std::vector<BoundaryGraph>> DrawingBoundaries(const std::vector<Drawing>& drawings) {
  std::vector<BoundaryGraph> graphs;
  for (int d = 0; d < static_cast<int>(drawings.size()); ++d) {
    absl::StatusOr<BoundaryGraph> g = BuildBoundaries(drawings[d], d + 1);
    if (!g.ok()) return g.status();
    graphs.push_back(*std::move(g));
  }
  if (absl::Status same = CheckSameEquivalence(graphs); !same.ok()) return same;
  return graphs;
}

// The boundary correspondence the options ask for, with the drawings' own marks when the options
// give none.
absl::StatusOr<BoundaryCorrespondence> Correspond(const std::vector<Drawing>& drawings,
                                                  const std::vector<BoundaryGraph>& graphs,
                                                  const MultimeshOptions& options,
                                                  bool match_corners) {
  BoundaryCorrespondenceOptions correspondence_options;
  correspondence_options.vertices = options.boundary_vertices;
  correspondence_options.corner_angle_degrees = options.corner_angle_degrees;
  correspondence_options.match_corners = match_corners;
  correspondence_options.alignment =
      options.correspondence == MultimeshOptions::Correspondence::kFeatures
          ? BoundaryCorrespondenceOptions::Alignment::kFeatures
          : BoundaryCorrespondenceOptions::Alignment::kArcLength;
  correspondence_options.tolerance = options.boundary_tolerance;
  correspondence_options.marks = options.marks;
  if (options.marks.empty()) {
    absl::StatusOr<std::vector<std::vector<Point>>> drawn = MarksFromDrawings(drawings);
    if (!drawn.ok()) return drawn.status();
    correspondence_options.marks = *std::move(drawn);
  }
  return ComputeBoundaryCorrespondence(graphs, correspondence_options);
}

// Two consecutive boundary vertices at one point would make a zero-length boundary edge in that
// drawing: refused, naming where, since more boundary vertices separate them.
absl::Status CheckDistinctSamples(const BoundaryCorrespondence& bc, int num_shapes) {
  for (int d = 0; d < num_shapes; ++d) {
    for (int g = 0; g < bc.num_loops(); ++g) {
      const Points& loop = bc.shapes[d][g];
      for (size_t k = 0; k < loop.size(); ++k) {
        if (loop[k] == loop[(k + 1) % loop.size()]) {
          return absl::InvalidArgumentError(
              absl::StrCat("drawing ", d + 1, ": two boundary vertices coincide near (",
                           loop[k].x(), ", ", loop[k].y(), "); use more boundary vertices"));
        }
      }
    }
  }
  return absl::OkStatus();
}

// next[e]: the correspondence edge after e on its loop (the loop closes).
std::vector<int> NextEdgeStarts(const BoundaryCorrespondence& bc) {
  std::vector<int> next_edge_start(bc.num_vertices());
  for (int g = 0; g < bc.num_loops(); ++g) {
    for (int e = bc.loop_start[g]; e < bc.loop_start[g + 1]; ++e) {
      next_edge_start[e] = e + 1 < bc.loop_start[g + 1] ? e + 1 : bc.loop_start[g];
    }
  }
  return next_edge_start;
}

// Correspondence vertex e (the start of edge e) in drawing d.
const Point& Sample(const BoundaryCorrespondence& bc, int d, int e) {
  const int g = static_cast<int>(std::upper_bound(bc.loop_start.begin(), bc.loop_start.end(), e) -
                                 bc.loop_start.begin()) -
                1;
  return bc.shapes[d][g][e - bc.loop_start[g]];
}

// The drawings in the order they are meshed, by rank. First the one with the most closed
// cut/opening sides: opening a slit (mapping out of the closed drawing) only widens angles, while
// closing a hole onto a slit asks the mesh for 2*pi at the slit tips; RefineBoundaryFans covers
// what remains. The next ranks (when the first drawing's mesh cannot be mapped into some drawing)
// follow in that order, ties in key order, up to kMaxReferences: a mesh of a concave drawing
// often maps onto a convex one when the other way round a chord of the convex drawing's mesh has
// nowhere to go.
std::vector<int> ReferenceOrder(const BoundaryCorrespondence& bc, int num_shapes) {
  std::vector<int> references(num_shapes);
  std::iota(references.begin(), references.end(), 0);
  std::vector<int> closed(num_shapes);
  for (int d = 0; d < num_shapes; ++d) {
    closed[d] = static_cast<int>(std::count_if(bc.edge_twin[d].begin(), bc.edge_twin[d].end(),
                                               [](int f) { return f >= 0; }));
  }
  std::stable_sort(references.begin(), references.end(),
                   [&](int a, int b) { return closed[a] > closed[b]; });
  return references;
}

// One attempt's construction once the reference drawing is chosen: its mesh cut open along the
// seams, boundary vertices made to pair up across every cohesive zone and fans widened, then an
// injective map of each component into every other drawing (overlaid where the attempt allows
// it), and the cohesive edges. A class because every phase reads and grows the same mesh; Build
// runs the phases in order.
class AttemptBuilder {
 public:
  AttemptBuilder(const BoundaryCorrespondence& bc, int ref, int num_shapes,
                 const MultimeshOptions& options, const AttemptOptions& attempt)
      : bc_(bc),
        ref_(ref),
        num_shapes_(num_shapes),
        num_edges_(bc.num_vertices()),
        options_(options),
        attempt_(attempt),
        next_edge_start_(NextEdgeStarts(bc)) {}

  absl::StatusOr<Multimesh> Build() {
    if (Cancelled(attempt_.cancel)) return absl::CancelledError("BuildMultimesh cancelled");
    Notify(attempt_.progress, "triangulate", 0.1,
           absl::StrCat("drawing ", ref_ + 1, ", ", num_edges_, " boundary vertices"));
    if (absl::Status s = MeshReference(); !s.ok()) return s;
    MirrorSteinerPoints();
    CollectBoundaryLoops();
    SplitBoundaryChords(&cut_.vertices, &cut_.triangles, &is_boundary_);
    WidenFans();
    mesh_.triangles = cut_.triangles;
    num_vertices_ = static_cast<int>(cut_.vertices.size());
    FindComponents();
    mesh_.shapes.assign(num_shapes_, {});
    mesh_.shapes[ref_] = TargetsOf(ref_);
    int done = 0;
    for (const int d : MapOrder()) {
      if (absl::Status s = MapDrawing(d, done++); !s.ok()) return s;
    }
    if (absl::Status s = PairCohesiveEdges(); !s.ok()) return s;
    for (int e : bc_.mark_vertices) mesh_.pinned.push_back(cut_.entries[e][0].vertex);
    return std::move(mesh_);
  }

  // Components reached by the overlay (MultimeshReport::overlays).
  int overlays() const { return overlays_; }

 private:
  // Mesh size for the reference drawing: max_edge from the options' relative length, else about
  // the even sampling's spacing (the refinement to the outline tolerance adds vertices at tips
  // only).
  TriangulateOptions ReferenceMeshOptions() const {
    TriangulateOptions triangulate_options;
    triangulate_options.shape_bound = options_.shape_bound;
    triangulate_options.max_vertices = options_.max_mesh_vertices;
    Point lo = bc_.shapes[ref_][0][0], hi = lo;
    double perimeter = 0.0;
    for (const Points& loop : bc_.shapes[ref_]) {
      for (size_t i = 0; i < loop.size(); ++i) {
        lo = lo.cwiseMin(loop[i]), hi = hi.cwiseMax(loop[i]);
        perimeter += (loop[(i + 1) % loop.size()] - loop[i]).norm();
      }
    }
    triangulate_options.max_edge =
        options_.max_edge_relative > 0
            ? options_.max_edge_relative * (hi - lo).norm()
            : 1.5 * perimeter / std::max(1, bc_.base_vertices > 0 ? bc_.base_vertices : num_edges_);
    return triangulate_options;
  }

  // The reference drawing's CGAL mesh, cut open along its seams (CutAlongSeams); errors name
  // the drawing.
  absl::Status MeshReference() {
    absl::StatusOr<DomainTriangulation> triangulation =
        CgalTriangulateDomain(bc_.shapes[ref_], ReferenceMeshOptions());
    if (!triangulation.ok()) {
      return Prefixed(triangulation.status(), absl::StrCat("drawing ", ref_ + 1, ": "));
    }
    absl::StatusOr<CutMesh> cut = CutAlongSeams(*triangulation, bc_);
    if (!cut.ok()) {
      return absl::Status(cut.status().code(),
                          absl::StrCat("drawing ", ref_ + 1, ": ", cut.status().message()));
    }
    cut_ = *std::move(cut);
    return absl::OkStatus();
  }

  // Mirror boundary Steiner points across every pair of twin edges of every drawing, so that
  // every cohesive edge pairs up in every drawing; a split can call for another on a third
  // edge, hence rounds (at most 8).
  void MirrorSteinerPoints() {
    for (int round = 0; round < 8; ++round) {
      bool split = false;
      for (int d = 0; d < num_shapes_; ++d) {
        for (int e = 0; e < num_edges_; ++e) {
          const int f = bc_.edge_twin[d][e];
          if (f < 0) continue;
          for (const BoundaryEntry& entry : std::vector<BoundaryEntry>(cut_.entries[e])) {
            if (entry.t == 0.0) continue;
            const double want = 1.0 - entry.t;
            bool present = false;
            for (const BoundaryEntry& other : cut_.entries[f])
              present |= std::abs(other.t - want) < 1e-9;
            if (!present) SplitBoundaryEdge(&cut_, next_edge_start_, f, want), split = true;
          }
        }
      }
      if (!split) break;
    }
  }

  // The mesh's boundary loops, edge by edge in correspondence order, and which vertices are on
  // the boundary.
  void CollectBoundaryLoops() {
    is_boundary_.assign(cut_.vertices.size(), false);
    for (int g = 0; g < bc_.num_loops(); ++g) {
      std::vector<int> loop;
      for (int e = bc_.loop_start[g]; e < bc_.loop_start[g + 1]; ++e) {
        for (const BoundaryEntry& entry : cut_.entries[e]) loop.push_back(entry.vertex);
      }
      for (int v : loop) is_boundary_[v] = true;
      mesh_.boundary.insert(mesh_.boundary.end(), loop.begin(), loop.end());
      mesh_.boundary_loops.push_back(std::move(loop));
    }
  }

  // Targets in drawing d: boundary vertices at their edge parameter, twins made exactly equal;
  // other vertices at their current place in the reference drawing.
  Points TargetsOf(int d) const {
    Points target = cut_.vertices;
    for (int e = 0; e < num_edges_; ++e) {
      const Point& a = Sample(bc_, d, e);
      const Point& b = Sample(bc_, d, next_edge_start_[e]);
      for (const BoundaryEntry& entry : cut_.entries[e]) {
        target[entry.vertex] = entry.t == 0.0 ? a : Point((1 - entry.t) * a + entry.t * b);
      }
    }
    for (int e = 0; e < num_edges_; ++e) {
      const int f = bc_.edge_twin[d][e];
      if (f < 0 || f < e) continue;
      const auto& le = cut_.entries[e];
      const auto& lf = cut_.entries[f];
      for (size_t j = 1; j < le.size() && j < lf.size(); ++j) {
        target[lf[lf.size() - j].vertex] = target[le[j].vertex];
      }
    }
    return target;
  }

  // The widest interior angle each boundary vertex must take in any drawing; fans too small for
  // it get more triangles (refine_boundary_fans.h).
  void WidenFans() {
    std::vector<double> demand(cut_.vertices.size(), 0.0);
    for (int d = 0; d < num_shapes_; ++d) {
      const Points target = TargetsOf(d);
      for (const std::vector<int>& loop : mesh_.boundary_loops) {
        for (size_t k = 0; k < loop.size(); ++k) {
          const int prev = loop[(k + loop.size() - 1) % loop.size()];
          const int next = loop[(k + 1) % loop.size()];
          demand[loop[k]] = std::max(
              demand[loop[k]], BoundaryInteriorAngle(target[prev], target[loop[k]], target[next]));
        }
      }
    }
    RefineBoundaryFans(demand, &cut_.vertices, &cut_.triangles, &is_boundary_);
  }

  // Connected components, each mapped on its own, and the boundary loops of each.
  void FindComponents() {
    component_of_.resize(num_vertices_);
    UnionFind components(num_vertices_);
    for (const Triangle& t : mesh_.triangles)
      components.Unite(t[0], t[1]), components.Unite(t[0], t[2]);
    for (int v = 0; v < num_vertices_; ++v) component_of_[v] = components.Find(v);
    for (int g = 0; g < bc_.num_loops(); ++g) {
      loops_of_component_[component_of_[mesh_.boundary_loops[g][0]]].push_back(g);
    }
  }

  // Drawings are mapped outward from the reference in key order (ref - 1, ref + 1, ref - 2,
  // ...), so that a pose the reference's mesh cannot reach directly finds a mapped neighbour to
  // start from (MapComponent).
  std::vector<int> MapOrder() const {
    std::vector<int> order;
    for (int d = 0; d < num_shapes_; ++d) {
      if (d != ref_) order.push_back(d);
    }
    const int ref = ref_;
    std::stable_sort(order.begin(), order.end(),
                     [ref](int a, int b) { return std::abs(a - ref) < std::abs(b - ref); });
    return order;
  }

  // Drawing d's shape, component by component; `k` drawings were mapped before it (progress).
  absl::Status MapDrawing(int d, int k) {
    if (Cancelled(attempt_.cancel)) return absl::CancelledError("BuildMultimesh cancelled");
    const double fraction = 0.2 + 0.75 * k / (num_shapes_ - 1);
    Notify(attempt_.progress, "map", fraction, absl::StrCat("drawing ", d + 1));
    Points shape = TargetsOf(d);
    const Points target = shape;
    for (const auto& [root, loops] : loops_of_component_) {
      if (absl::Status s = MapComponentInto(d, root, loops, target, fraction, &shape); !s.ok()) {
        return s;
      }
    }
    mesh_.shapes[d] = std::move(shape);
    return absl::OkStatus();
  }

  // One component's map into drawing d written into *shape: found directly (MapOrReplay), else
  // with the attempt's overlay (which grows the mesh, and *shape with it), else the nearly flat
  // map the overlay was to improve on. Errors name both drawings.
  absl::Status MapComponentInto(int d, int root, const std::vector<int>& loops,
                                const Points& target, double fraction, Points* shape) {
    const bool overlay = attempt_.mode.overlay;
    Component c = ExtractComponent(mesh_, component_of_, root, loops, target);
    std::optional<Points> flat_map;
    absl::StatusOr<Points> mapped = MapOrReplay(c, d, root, &flat_map);
    if (!mapped.ok() && overlay && absl::IsFailedPrecondition(mapped.status())) {
      Notify(attempt_.progress, "map", fraction,
             absl::StrCat("drawing ", d + 1, ": ", mapped.status().message(),
                          "; overlaying the mesh with a triangulation of drawing ", d + 1));
      const Growing growing{&mesh_, &component_of_, &cut_.vertices, &num_vertices_};
      mapped = OverlayComponent(&c, root, ref_, d, options_, growing, attempt_.cancel);
      if (absl::IsCancelled(mapped.status())) return mapped.status();
      if (mapped.ok()) ++overlays_;
      shape->resize(num_vertices_);
    }
    if (!mapped.ok() && overlay && flat_map.has_value() && !absl::IsCancelled(mapped.status())) {
      mapped = *std::move(flat_map);  // the overlay did not build: the flat map is all there is
    }
    if (!mapped.ok()) return MapError(mapped.status(), d);
    for (size_t i = 0; i < c.global.size(); ++i) (*shape)[c.global[i]] = (*mapped)[i];
    return absl::OkStatus();
  }

  // MapComponent's answer for component `root` in drawing d. With the memo, an attempt without
  // overlay records it; one with overlay replays it until its first overlay, since up to there
  // it asks for exactly the maps the first attempt made (the construction is deterministic).
  absl::StatusOr<Points> MapOrReplay(const Component& c, int d, int root,
                                     std::optional<Points>* flat_map) {
    MapMemo* memo = attempt_.memo;
    const bool overlay = attempt_.mode.overlay;
    const std::pair<int, int> key(d, root);
    if (memo != nullptr && overlay && overlays_ == 0) {
      if (auto it = memo->entries.find(key); it != memo->entries.end()) {
        *flat_map = it->second.flat_map;
        return it->second.mapped;
      }
    }
    absl::StatusOr<Points> mapped =
        MapComponent(c, mesh_, ref_, d, options_, attempt_.cancel, flat_map);
    if (memo != nullptr && !overlay && !absl::IsCancelled(mapped.status())) {
      memo->entries[key] = {mapped, *flat_map};
    }
    return mapped;
  }

  // A map not found, as the attempt's answer: out of memory and cancellation kept as such,
  // anything else FAILED_PRECONDITION (the caller may try another drawing's mesh).
  absl::Status MapError(const absl::Status& status, int d) const {
    if (absl::IsCancelled(status)) return status;
    if (absl::IsResourceExhausted(status)) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "mapping drawing ", ref_ + 1, "'s mesh into drawing ", d + 1, ": ", status.message()));
    }
    return absl::FailedPreconditionError(absl::StrCat(
        "cannot map drawing ", ref_ + 1, "'s mesh into drawing ", d + 1, ": ", status.message()));
  }

  // Cohesive edges: sub-edges of twin edges, closed in the drawings where they are collocated.
  absl::Status PairCohesiveEdges() {
    std::map<std::array<int, 4>, int> cohesive_index;
    mesh_.cohesive_closed.assign(num_shapes_, {});
    for (int d = 0; d < num_shapes_; ++d) {
      for (int e = 0; e < num_edges_; ++e) {
        const int f = bc_.edge_twin[d][e];
        if (f < 0 || f < e) continue;
        std::vector<int> le, lf;
        for (const BoundaryEntry& x : cut_.entries[e]) le.push_back(x.vertex);
        le.push_back(cut_.entries[next_edge_start_[e]][0].vertex);
        for (const BoundaryEntry& x : cut_.entries[f]) lf.push_back(x.vertex);
        lf.push_back(cut_.entries[next_edge_start_[f]][0].vertex);
        if (le.size() != lf.size()) {
          return absl::InternalError("cohesive sides have different vertex counts");
        }
        const size_t m = le.size() - 1;
        for (size_t j = 0; j < m; ++j) {
          const std::array<int, 4> c = {le[j], le[j + 1], lf[m - j], lf[m - j - 1]};
          auto [it, inserted] =
              cohesive_index.emplace(c, static_cast<int>(mesh_.cohesive_edges.size()));
          if (inserted) mesh_.cohesive_edges.push_back(c);
          mesh_.cohesive_closed[d].push_back(it->second);
        }
      }
    }
    if (mesh_.cohesive_edges.empty()) mesh_.cohesive_closed.clear();
    return absl::OkStatus();
  }

  const BoundaryCorrespondence& bc_;
  const int ref_;         // the drawing meshed
  const int num_shapes_;  // drawings
  const int num_edges_;   // correspondence edges (= correspondence vertices)
  const MultimeshOptions& options_;
  const AttemptOptions& attempt_;
  const std::vector<int> next_edge_start_;  // NextEdgeStarts
  CutMesh cut_;                             // the reference drawing's mesh, cut open
  std::vector<bool> is_boundary_;           // per vertex of cut_
  Multimesh mesh_;
  int num_vertices_ = 0;                                // grows with the overlay
  std::vector<int> component_of_;                       // per mesh vertex: its component's root
  std::map<int, std::vector<int>> loops_of_component_;  // component root -> its boundary loops
  int overlays_ = 0;
};

// The built mesh checked (ValidateMultimesh), then the drawings' art embedded in it
// (art_embedding.h), which rides the mesh from here on; *art_seconds: how long that took.
absl::Status ValidateAndEmbedArt(const std::vector<Drawing>& drawings, const ProgressFn& progress,
                                 Multimesh* mesh, double* art_seconds) {
  Notify(progress, "validate", 0.95, absl::StrCat(mesh->num_vertices(), " vertices"));
  if (absl::Status valid = ValidateMultimesh(*mesh); !valid.ok()) {
    return absl::InternalError(absl::StrCat("built multimesh is invalid: ", valid.message()));
  }
  const auto art_start = std::chrono::steady_clock::now();
  absl::StatusOr<std::vector<EmbeddedArt>> art = EmbedDrawingsArt(*mesh, drawings);
  if (!art.ok()) return art.status();
  mesh->art = *std::move(art);
  *art_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - art_start).count();
  return absl::OkStatus();
}

// A successful attempt's numbers (MultimeshReport); `start`: when the attempt began.
void FillReport(const Multimesh& mesh, const BoundaryCorrespondence& bc,
                const std::vector<BoundaryGraph>& graphs, int overlays, double art_seconds,
                std::chrono::steady_clock::time_point start, MultimeshReport* report) {
  report->art_seconds = art_seconds;
  report->vertices = mesh.num_vertices();
  report->triangles = static_cast<int>(mesh.triangles.size());
  report->boundary_loops = static_cast<int>(mesh.boundary_loops.size());
  report->cohesive_edges = static_cast<int>(mesh.cohesive_edges.size());
  report->corner_matched_loops = bc.corner_matched_loops;
  report->loop_vertices.clear();
  for (const std::vector<int>& loop : mesh.boundary_loops) {
    report->loop_vertices.push_back(static_cast<int>(loop.size()));
  }
  report->achieved_tolerance = bc.achieved_tolerance;
  report->overlays = overlays;
  report->equivalence.clear();
  for (const BoundaryGraph& g : graphs) report->equivalence.push_back(g.equivalence.ToString());
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// One attempt of BuildMultimesh: boundaries, correspondence (corners matched or not), then the
// drawing of the given rank in ReferenceOrder meshed and mapped (*meshed: which drawing that
// is). Returns ABORTED (not an answer: the caller keeps its first error) with require_match when
// no loop's corners matched, and when there is no drawing of that rank, before any meshing.
absl::StatusOr<Multimesh> BuildOnce(const std::vector<Drawing>& drawings,
                                    const MultimeshOptions& options, const AttemptOptions& attempt,
                                    MultimeshReport* report, int* meshed) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = CheckDrawings(drawings); !s.ok()) return s;
  const int num_shapes = static_cast<int>(drawings.size());
  if (Cancelled(attempt.cancel)) return absl::CancelledError("BuildMultimesh cancelled");
  Notify(attempt.progress, "boundaries", 0.0, absl::StrCat(num_shapes, " drawings"));
  absl::StatusOr<std::vector<BoundaryGraph>> graphs = DrawingBoundaries(drawings);
  if (!graphs.ok()) return graphs.status();

  Notify(attempt.progress, "correspondence", 0.05,
         absl::StrCat((*graphs)[0].loops.size(), " boundary loops"));
  absl::StatusOr<BoundaryCorrespondence> bc =
      Correspond(drawings, *graphs, options, attempt.mode.match_corners);
  if (!bc.ok()) return bc.status();
  if (attempt.mode.require_match && bc->corner_matched_loops == 0) {
    return absl::AbortedError("no loop has corners to match");
  }
  if (absl::Status s = CheckDistinctSamples(*bc, num_shapes); !s.ok()) return s;
  if (attempt.rank >= std::min(num_shapes, kMaxReferences)) {
    return absl::AbortedError("no other drawing to mesh");
  }
  const int ref = ReferenceOrder(*bc, num_shapes)[attempt.rank];
  if (meshed != nullptr) *meshed = ref;

  AttemptBuilder builder(*bc, ref, num_shapes, options, attempt);
  absl::StatusOr<Multimesh> mesh = builder.Build();
  if (!mesh.ok()) return mesh.status();
  // Vertices along a Hilbert curve of the first shape: every later stage loops over triangles
  // and gathers their corners (vertex_order.h).
  RenumberSpatially(&*mesh);
  double art_seconds = 0.0;
  if (absl::Status s = ValidateAndEmbedArt(drawings, attempt.progress, &*mesh, &art_seconds);
      !s.ok()) {
    return s;
  }
  if (report != nullptr) {
    FillReport(*mesh, *bc, *graphs, builder.overlays(), art_seconds, start, report);
  }
  Notify(attempt.progress, "done", 1.0,
         absl::StrCat(mesh->num_vertices(), " vertices, ", mesh->triangles.size(), " triangles"));
  return mesh;
}

}  // namespace

absl::StatusOr<Multimesh> BuildMultimesh(const std::vector<Drawing>& drawings,
                                         const MultimeshOptions& options, const CancelToken* cancel,
                                         const ProgressFn& progress, MultimeshReport* report) {
  using CornerMatching = MultimeshOptions::CornerMatching;
  // Progress stays monotone across the attempts.
  double reached = 0.0;
  const ProgressFn monotone = [&](const std::string& stage, double fraction,
                                  const std::string& detail) {
    reached = std::max(reached, fraction);
    if (progress) progress(stage, reached, detail);
  };
  const bool arc_length = options.corner_matching != CornerMatching::kAlways;
  const bool corners = options.corner_matching != CornerMatching::kNever;
  // Per reference drawing (rank), arc length and then corners matched; the next reference only
  // when the first one's meshes could not be mapped (FAILED_PRECONDITION). The first attempt's
  // error is the answer when nothing builds.
  absl::Status first;  // the first attempt's error (OK until an attempt fails)
  MapMemo memo;        // the first attempt's maps, for the overlay attempt
  std::string others;  // the drawings meshed after the first, when none of them built
  int num_others = 0;
  for (int rank = 0; rank < kMaxReferences; ++rank) {
    int meshed = -1;
    auto attempt = [&](AttemptMode mode) -> std::optional<absl::StatusOr<Multimesh>> {
      // The first attempt (rank 0, the first correspondence) is the one the overlay repeats.
      const bool first_attempt =
          rank == 0 && mode.match_corners == !arc_length && !mode.require_match;
      const AttemptOptions attempt_options{
          .mode = mode,
          .rank = rank,
          .memo = first_attempt && options.overlay ? &memo : nullptr,
          .cancel = cancel,
          .progress = monotone};
      absl::StatusOr<Multimesh> m = BuildOnce(drawings, options, attempt_options, report, &meshed);
      if (m.ok() || absl::IsCancelled(m.status())) return m;
      if (rank == 0 && first.ok()) first = m.status();
      return std::nullopt;
    };
    if (rank > 0) {
      if (!absl::IsFailedPrecondition(first)) break;
      monotone("triangulate", reached,
               absl::StrCat(first.message(), "; again with another drawing's mesh"));
    }
    if (arc_length) {
      if (auto built = attempt({.match_corners = false})) return *built;
      if (rank == 0 && !absl::IsInvalidArgument(first) && !absl::IsFailedPrecondition(first)) {
        return first;
      }
      if (rank > 0 && meshed < 0) break;  // no drawing of this rank
      if (corners) {
        monotone("correspondence", reached,
                 rank == 0 ? absl::StrCat("by arc length: ", first.message(),
                                          "; again with corners matched to corners")
                           : std::string("again with corners matched to corners"));
      }
    }
    if (corners) {
      if (auto built = attempt({.match_corners = true, .require_match = arc_length})) {
        return *built;
      }
    }
    if (meshed < 0) break;  // no drawing of this rank: nothing was tried
    if (rank > 0) absl::StrAppend(&others, num_others++ > 0 ? ", " : "", meshed + 1);
  }
  std::string overlay_note;  // why the overlay did not build either
  if (options.overlay && absl::IsFailedPrecondition(first)) {
    monotone(
        "map", reached,
        absl::StrCat(first.message(), "; again, overlaying the mesh where it cannot be mapped"));
    const AttemptOptions overlay_attempt{
        .mode = {.match_corners = !arc_length, .require_match = false, .overlay = true},
        .rank = 0,
        .memo = &memo,
        .cancel = cancel,
        .progress = monotone};
    absl::StatusOr<Multimesh> m = BuildOnce(drawings, options, overlay_attempt, report, nullptr);
    if (m.ok() || absl::IsCancelled(m.status())) return m;
    overlay_note = absl::StrCat("; overlaid: ", m.status().message());
  }
  if (num_others == 0) {
    return overlay_note.empty()
               ? first
               : absl::Status(first.code(), absl::StrCat(first.message(), overlay_note));
  }
  return absl::FailedPreconditionError(absl::StrCat(
      first.message(), num_others == 1 ? " (the mesh of drawing " : " (the meshes of drawings ",
      others, " did not map either)", overlay_note));
}

}  // namespace inbetween::solver
