// Quality triangulation of a simple polygon: CGAL Constrained_Delaunay_triangulation_2 of the
// boundary, refined by CGAL::refine_Delaunay_mesh_2 with Delaunay_mesh_size_criteria_2. The
// faces inside the polygon (the bounded domain) are returned with positive orientation, and
// every Steiner point that landed on a boundary segment is reported with its segment parameter.
//
// THE ONLY FILE IN THE PROJECT THAT INCLUDES CGAL.
#include "solver/mesh/cgal_triangulate.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <stdexcept>

#include "absl/strings/str_cat.h"
#include "solver/core/error_reason.h"
#include "solver/geometry/polygon.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

// The kernel and data structures, named once.
using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;

// A refinement point is a circumcentre (or an edge midpoint) constructed in doubles. For a face
// that is flat to double precision the circumcentre overflows to inf or lands absurdly far away,
// and the mesher then hands it to the exact predicates, whose conversion of inf to a GMP
// rational raises SIGFPE (seen on real icons with near-zero-angle cusps). The kernel below
// refuses such a point with an exception, caught by the triangulation functions.
struct RefinementPointError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
struct GuardedKernel : public Epick {
  struct Construct_circumcenter_2 : public Epick::Construct_circumcenter_2 {
    using Base = Epick::Construct_circumcenter_2;
    using Base::operator();
    Epick::Point_2 operator()(const Epick::Point_2& p, const Epick::Point_2& q,
                              const Epick::Point_2& r) const {
      const Epick::Point_2 c = Base::operator()(p, q, r);
      const double scale = std::max({std::abs(p.x()), std::abs(p.y()), std::abs(q.x()),
                                     std::abs(q.y()), std::abs(r.x()), std::abs(r.y()), 1.0});
      if (!std::isfinite(c.x()) || !std::isfinite(c.y()) || std::abs(c.x()) > 1e12 * scale ||
          std::abs(c.y()) > 1e12 * scale) {
        throw RefinementPointError(absl::StrCat(
            "triangulate: the drawing has a cusp or boundaries that nearly touch near (", p.x(),
            ", ", p.y(),
            "): a triangle there is flat to double precision; widen the cusp or "
            "separate the boundaries"));
      }
      return c;
    }
  };
  Construct_circumcenter_2 construct_circumcenter_2_object() const { return {}; }
};
using K = GuardedKernel;

// Where the refinement put its last point: the mesher offers no hook per inserted point, but
// every insertion sets the new vertex's point (Triangulation_2::insert*), so a vertex base that
// records set_point sees each one (per thread: a server meshes on several threads at once).
struct LastInserted {
  bool set = false;
  double x = 0.0, y = 0.0;
};
thread_local LastInserted last_inserted;

template <class Gt, class Vb0 = CGAL::Triangulation_vertex_base_2<Gt>>
class RecordingVertexBase : public CGAL::Delaunay_mesh_vertex_base_2<Gt, Vb0> {
  using Base = CGAL::Delaunay_mesh_vertex_base_2<Gt, Vb0>;

 public:
  template <typename TDS2>
  struct Rebind_TDS {
    using Vb2 = typename Vb0::template Rebind_TDS<TDS2>::Other;
    using Other = RecordingVertexBase<Gt, Vb2>;
  };
  using Base::Base;
  void set_point(const typename Base::Point& p) {
    Base::set_point(p);
    last_inserted = {true, CGAL::to_double(p.x()), CGAL::to_double(p.y())};
  }
};

using Vb = RecordingVertexBase<K>;
using Fb = CGAL::Delaunay_mesh_face_base_2<K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<Cdt>;

using CgalPoint = K::Point_2;
using VertexHandle = Cdt::Vertex_handle;

// Refinement stops when a new point lands closer than this to a neighbour, relative to the
// input's bounding-box diagonal. Delaunay refinement cannot resolve a cusp (two boundary edges at
// a near-zero angle) or boundaries that nearly touch: it splits ever smaller edges there until
// the inexact constructions give coincident points and CGAL's data structure breaks (a crash,
// seen on real icons). 1e-7 is far below any spacing a mesh within max_vertices needs and far
// above where double constructions fail.
constexpr double kMinRefinementSpacing = 1e-7;
// The same bound on the input's own points (checked before the mesher runs), ten times lower:
// a drawing may hold points closer than the refinement would construct and still mesh (the
// icon `filetype-scss`: a boundary segment 7e-8 of the diagonal long where a straight side meets
// a curve), while the fuzz input that broke CGAL's edge refinement had two corners 8e-11 of it
// apart.
constexpr double kMinInputSpacing = 1e-8;

// CGAL::refine_Delaunay_mesh_2, one step at a time so that it can stop at `max_vertices` and
// before a point closer than kMinRefinementSpacing of the input's diagonal to its neighbours.
absl::Status RefineBounded(Cdt& cdt, const Criteria& criteria, int max_vertices, double diagonal) {
  const double min_spacing = kMinRefinementSpacing * diagonal;
  const double min_input_spacing = kMinInputSpacing * diagonal;
  // Input points already that close (a needle folded back on itself, two boundaries nearly
  // touching) get the same answer before the mesher sees them: its edge refinement can fail an
  // internal assertion on them before the first point is inserted (mesh_fuzz finding,
  // build/fuzz/artifacts/mesh_fuzz/crash-5252cc03…: two corners 2.75e-9 apart).
  for (auto e = cdt.finite_edges_begin(); e != cdt.finite_edges_end(); ++e) {
    const CgalPoint& a = e->first->vertex(Cdt::ccw(e->second))->point();
    const CgalPoint& b = e->first->vertex(Cdt::cw(e->second))->point();
    const double d = std::sqrt(CGAL::to_double(CGAL::squared_distance(a, b)));
    if (d < min_input_spacing) {
      return absl::InvalidArgumentError(
          absl::StrCat("triangulate: the drawing has a cusp or boundaries that nearly touch near (",
                       a.x(), ", ", a.y(), "): two of its points are ", d, " apart (less than ",
                       min_input_spacing, "); widen the cusp or separate the boundaries"));
    }
  }
  CGAL::Delaunay_mesher_2<Cdt, Criteria> mesher(cdt, criteria);
  mesher.init();
  Cdt::Face_handle hint;
  while (!mesher.is_refinement_done()) {
    last_inserted.set = false;
    mesher.try_one_step_refine_mesh();
    if (max_vertices > 0 && cdt.number_of_vertices() > static_cast<size_t>(max_vertices)) {
      return WithReason(
          absl::ResourceExhaustedError(absl::StrCat(
              "triangulate: refinement needs more than ", max_vertices,
              " vertices (a part of the drawing is far thinner than the rest: a sliver, a spike "
              "or boundaries that nearly touch)")),
          kReasonMeshVertexLimit);
    }
    if (!last_inserted.set) continue;
    const CgalPoint p(last_inserted.x, last_inserted.y);
    Cdt::Locate_type type;
    int li;
    hint = cdt.locate(p, type, li, hint);
    if (type != Cdt::VERTEX) continue;
    const VertexHandle v = hint->vertex(li);
    double nearest = std::numeric_limits<double>::infinity();
    auto w = cdt.incident_vertices(v), done = w;
    do {
      if (!cdt.is_infinite(w))
        nearest =
            std::min(nearest, std::sqrt(CGAL::to_double(CGAL::squared_distance(p, w->point()))));
    } while (++w != done);
    if (nearest < min_spacing) {
      return absl::InvalidArgumentError(absl::StrCat(
          "triangulate: the drawing has a cusp or boundaries that nearly touch near (",
          last_inserted.x, ", ", last_inserted.y, "): the mesh would need triangles smaller than ",
          min_spacing, " there; widen the cusp or separate the boundaries"));
    }
  }
  return absl::OkStatus();
}

double Diagonal(const std::vector<Points>& loops) {
  Point lo(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  Point hi = -lo;
  for (const Points& loop : loops) {
    for (const Point& p : loop) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

// The mesher's pass over a triangulation whose constraints are in place: with options.refine,
// Delaunay refinement to the size and shape bounds (RefineBounded; `loops` give the scale of its
// spacing bound), else only the set-up, which marks the enclosed faces and inserts nothing. Shared
// by both entry points so that they refine alike.
absl::Status MeshConstrained(Cdt& cdt, const TriangulateOptions& options,
                             const std::vector<Points>& loops) {
  const double size = options.max_edge > 0 ? options.max_edge : 0.0;
  if (!options.refine) {
    CGAL::Delaunay_mesher_2<Cdt, Criteria> mesher(cdt, Criteria(options.shape_bound, size));
    mesher.init();
    return absl::OkStatus();
  }
  return RefineBounded(cdt, Criteria(options.shape_bound, size), options.max_vertices,
                       Diagonal(loops));
}

// The loops' points inserted once each (points repeated exactly, as a slit walked both ways,
// share a vertex), then every loop edge as a constraint. Fails when two points merge (too close)
// or constraints cross, since either would change the loops' vertex count.
absl::Status InsertLoops(const std::vector<Points>& loops, Cdt& cdt,
                         std::vector<VertexHandle>* handles,
                         std::vector<std::vector<VertexHandle>>* loop_handles) {
  std::map<std::pair<double, double>, VertexHandle> by_point;
  loop_handles->resize(loops.size());
  for (size_t l = 0; l < loops.size(); ++l) {
    for (const Point& p : loops[l]) {
      auto [it, inserted] = by_point.emplace(std::make_pair(p.x(), p.y()), VertexHandle());
      if (inserted) {
        it->second = cdt.insert(CgalPoint(p.x(), p.y()));
        handles->push_back(it->second);
      }
      (*loop_handles)[l].push_back(it->second);
    }
  }
  const size_t distinct = cdt.number_of_vertices();
  if (distinct != handles->size()) {
    return absl::InvalidArgumentError("triangulate: loop points are too close to each other");
  }
  for (const auto& lh : *loop_handles) {
    for (size_t k = 0; k < lh.size(); ++k) {
      if (lh[k] != lh[(k + 1) % lh.size()]) cdt.insert_constraint(lh[k], lh[(k + 1) % lh.size()]);
    }
  }
  if (cdt.number_of_vertices() != distinct) {
    return absl::InvalidArgumentError("triangulate: boundary loops cross each other");
  }
  return absl::OkStatus();
}

// Output numbering: the distinct loop points in insertion order, then the Steiner points in
// CGAL's vertex order (insertion order), so that the numbering is deterministic.
std::map<VertexHandle, int> NumberVertices(const Cdt& cdt, const std::vector<VertexHandle>& handles,
                                           Points* vertices) {
  std::map<VertexHandle, int> index;
  for (VertexHandle h : handles) {
    index[h] = static_cast<int>(vertices->size());
    vertices->emplace_back(h->point().x(), h->point().y());
  }
  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
    if (index.count(v)) continue;
    index[v] = static_cast<int>(vertices->size());
    vertices->emplace_back(v->point().x(), v->point().y());
  }
  return index;
}

// The mesher's domain is every region enclosed by constraints (it also fills holes: marking the
// domain ourselves made the 5.5 mesher loop on concave shapes), so faces are kept by the
// even-odd rule over the loops at their centroid, positively oriented.
void KeepEvenOddFaces(const Cdt& cdt, const std::vector<Points>& loops,
                      const std::map<VertexHandle, int>& index, DomainTriangulation* out) {
  // Each loop's bounding box first: a centroid outside it is outside the loop (a drawing of
  // 900 holes spent 3.6 s here testing 218k centroids against every loop).
  std::vector<Eigen::AlignedBox2d> boxes(loops.size());
  for (size_t l = 0; l < loops.size(); ++l) {
    for (const Point& p : loops[l]) boxes[l].extend(p);
  }
  auto in_domain = [&](const Point& q) {
    bool in = false;
    for (size_t l = 0; l < loops.size(); ++l) {
      if (boxes[l].contains(q)) in ^= PolygonContains(loops[l], q);
    }
    return in;
  };
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->is_in_domain()) continue;
    Triangle t = {index.at(f->vertex(0)), index.at(f->vertex(1)), index.at(f->vertex(2))};
    if (!in_domain((out->vertices[t[0]] + out->vertices[t[1]] + out->vertices[t[2]]) / 3.0)) {
      continue;
    }
    if (SignedArea2(t, out->vertices) < 0) std::swap(t[1], t[2]);
    out->triangles.push_back(t);
  }
}

// The Steiner vertices refinement put on the loop edge from `from` (at point a) to `to` (at
// a + d), in order: walks constrained edges, each step to the nearest vertex further along the
// edge's line (within 1e-9 of its length off it). INTERNAL when the walk cannot reach `to`.
absl::Status SteinerChain(const Cdt& cdt, const std::map<VertexHandle, int>& index,
                          VertexHandle from, VertexHandle to, const Point& a, const Point& d,
                          std::vector<int>* chain) {
  const double len2 = d.squaredNorm();
  VertexHandle current = from;
  double current_t = 0.0;
  for (int guard = 0; current != to && guard < 1000000; ++guard) {
    VertexHandle best;
    double best_t = 2.0;
    auto e = cdt.incident_edges(current), done = e;
    do {
      if (cdt.is_infinite(*e) || !cdt.is_constrained(*e)) continue;
      VertexHandle w = e->first->vertex(Cdt::cw(e->second));
      if (w == current) w = e->first->vertex(Cdt::ccw(e->second));
      const Point q(w->point().x(), w->point().y());
      const double t = (q - a).dot(d) / len2;
      const double off = std::abs(Cross(d, q - a)) / std::sqrt(len2);
      if (t > current_t && t < best_t && off <= 1e-9 * std::sqrt(len2)) best = w, best_t = t;
    } while (++e != done);
    if (best == VertexHandle()) {
      return absl::InternalError("triangulate: lost a boundary edge during refinement");
    }
    if (best != to) chain->push_back(index.at(best));
    current = best;
    current_t = best_t;
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<PolygonTriangulation> CgalTriangulate(const Points& boundary,
                                                     const TriangulateOptions& options) {
  const int n = static_cast<int>(boundary.size());
  if (n < 3) return absl::InvalidArgumentError("triangulate: polygon has fewer than 3 points");
  if (!(PolygonSignedArea2(boundary) > 0)) {
    return absl::InvalidArgumentError("triangulate: polygon must have positive signed area");
  }
  if (!(options.shape_bound > 0)) {
    return absl::InvalidArgumentError("triangulate: shape_bound must be > 0");
  }

  PolygonTriangulation out;
  try {
    Cdt cdt;
    std::vector<VertexHandle> handles(n);
    for (int i = 0; i < n; ++i) {
      handles[i] = cdt.insert(CgalPoint(boundary[i].x(), boundary[i].y()));
    }
    if (static_cast<int>(cdt.number_of_vertices()) != n) {
      return absl::InvalidArgumentError("triangulate: polygon has repeated points");
    }
    for (int i = 0; i < n; ++i) cdt.insert_constraint(handles[i], handles[(i + 1) % n]);
    if (static_cast<int>(cdt.number_of_vertices()) != n) {
      // Constraint intersections add vertices: the polygon was not simple.
      return absl::InvalidArgumentError("triangulate: polygon boundary crosses itself");
    }

    if (absl::Status s = MeshConstrained(cdt, options, {boundary}); !s.ok()) return s;

    std::map<VertexHandle, int> index;
    for (int i = 0; i < n; ++i) index[handles[i]] = i;
    out.vertices = boundary;
    // Steiner points in a deterministic order: CGAL's vertex iteration order (insertion order).
    for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
      if (index.count(v)) continue;
      index[v] = static_cast<int>(out.vertices.size());
      out.vertices.emplace_back(v->point().x(), v->point().y());
    }
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
      if (!f->is_in_domain()) continue;
      Triangle t = {index.at(f->vertex(0)), index.at(f->vertex(1)), index.at(f->vertex(2))};
      if (SignedArea2(t, out.vertices) < 0) std::swap(t[1], t[2]);
      out.triangles.push_back(t);
    }
    // Steiner vertices on a constrained edge lie on the boundary: find their segment.
    for (auto e = cdt.finite_edges_begin(); e != cdt.finite_edges_end(); ++e) {
      if (!cdt.is_constrained(*e)) continue;
      for (int k : {1, 2}) {
        const VertexHandle v = e->first->vertex((e->second + k) % 3);
        const int vi = index.at(v);
        if (vi < n) continue;
        if (std::any_of(out.boundary_steiner.begin(), out.boundary_steiner.end(),
                        [&](const BoundarySteiner& b) { return b.vertex == vi; })) {
          continue;
        }
        const Point p = out.vertices[vi];
        BoundarySteiner best{vi, -1, 0.0};
        double best_distance = std::numeric_limits<double>::infinity();
        for (int s = 0; s < n; ++s) {
          const Point& a = boundary[s];
          const Point& b = boundary[(s + 1) % n];
          const double t = SegmentParameter(p, a, b);
          const double dist = (a + t * (b - a) - p).norm();
          if (dist < best_distance) best_distance = dist, best.segment = s, best.t = t;
        }
        out.boundary_steiner.push_back(best);
      }
    }
    std::sort(out.boundary_steiner.begin(), out.boundary_steiner.end(),
              [](const BoundarySteiner& a, const BoundarySteiner& b) {
                return a.segment < b.segment || (a.segment == b.segment && a.t < b.t);
              });
  } catch (const RefinementPointError& e) {
    return absl::InvalidArgumentError(e.what());
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("triangulate: CGAL failed: ", e.what()));
  }
  if (out.triangles.empty()) return absl::InternalError("triangulate: no triangle inside");
  return out;
}

absl::StatusOr<DomainTriangulation> CgalTriangulateDomain(const std::vector<Points>& loops,
                                                          const TriangulateOptions& options) {
  if (loops.empty()) return absl::InvalidArgumentError("triangulate: no boundary loop");
  for (const Points& loop : loops) {
    if (loop.size() < 2) return absl::InvalidArgumentError("triangulate: a loop has < 2 points");
  }
  if (!(options.shape_bound > 0)) {
    return absl::InvalidArgumentError("triangulate: shape_bound must be > 0");
  }
  DomainTriangulation out;
  try {
    Cdt cdt;
    std::vector<VertexHandle> handles;
    std::vector<std::vector<VertexHandle>> loop_handles;
    if (absl::Status s = InsertLoops(loops, cdt, &handles, &loop_handles); !s.ok()) return s;
    if (absl::Status s = MeshConstrained(cdt, options, loops); !s.ok()) return s;
    const std::map<VertexHandle, int> index = NumberVertices(cdt, handles, &out.vertices);
    KeepEvenOddFaces(cdt, loops, index, &out);
    out.loop_vertex.resize(loops.size());
    out.edge_chain.resize(loops.size());
    for (size_t l = 0; l < loops.size(); ++l) {
      const auto& lh = loop_handles[l];
      for (size_t k = 0; k < lh.size(); ++k) {
        out.loop_vertex[l].push_back(index.at(lh[k]));
        const Point a = loops[l][k], d = loops[l][(k + 1) % lh.size()] - a;
        std::vector<int> chain;
        if (absl::Status s = SteinerChain(cdt, index, lh[k], lh[(k + 1) % lh.size()], a, d, &chain);
            !s.ok()) {
          return s;
        }
        out.edge_chain[l].push_back(std::move(chain));
      }
    }
  } catch (const RefinementPointError& e) {
    return absl::InvalidArgumentError(e.what());
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("triangulate: CGAL failed: ", e.what()));
  }
  if (out.triangles.empty()) return absl::InternalError("triangulate: no triangle inside");
  return out;
}

}  // namespace inbetween::solver
