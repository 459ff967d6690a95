// Quality triangulation of a simple polygon (CGAL constrained Delaunay + Delaunay refinement).
// The only CGAL user in the project is cgal_triangulate.cpp; this header is CGAL-free.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct TriangulateOptions {
  // Upper bound on triangle edge length, in the polygon's units (<= 0: no size bound).
  double max_edge = 0.0;
  // Delaunay_mesh_size_criteria_2 shape bound B = 1 / (4 sin^2(min angle)); 0.125 ~ 20.7 deg,
  // the smallest value for which refinement is guaranteed to terminate.
  double shape_bound = 0.125;
  // Refinement stops with RESOURCE_EXHAUSTED above this many vertices (<= 0: no bound). A
  // sliver or spike far thinner than the rest of the drawing needs elements at its own scale
  // all along it: millions of points, i.e. no answer in practice (mesh_fuzz finding).
  int max_vertices = 2'000'000;
  // false: the constrained Delaunay triangulation of the boundary alone (no Steiner point; the
  // size and shape bounds are ignored).
  bool refine = true;
};

// A Steiner vertex the mesher put on the polygon boundary, on segment `segment` (from
// boundary[segment] to boundary[(segment + 1) % n]) at parameter t in (0, 1).
struct BoundarySteiner {
  int vertex = 0;
  int segment = 0;
  double t = 0.0;
};

struct PolygonTriangulation {
  Points vertices;                  // the n boundary points in the given order, then Steiner
  std::vector<Triangle> triangles;  // all positive (types.h)
  std::vector<BoundarySteiner> boundary_steiner;  // sorted by (segment, t)
};

// `boundary` must be a simple polygon of positive signed area with distinct points.
// Errors: INVALID_ARGUMENT for fewer than 3 points or non-positive area, INTERNAL if CGAL fails.
absl::StatusOr<PolygonTriangulation> CgalTriangulate(const Points& boundary,
                                                     const TriangulateOptions& options = {});

// A domain bounded by several closed loops (outer loops positive, holes negative, slits and
// cut sides walked both ways with exactly equal points), triangulated as one CDT: every distinct
// point once, every loop edge a constraint. Faces are in the domain by the even-odd rule over
// the loops (slits and cuts, walked twice, do not change it).
struct DomainTriangulation {
  Points vertices;                            // distinct loop points first, then Steiner points
  std::vector<Triangle> triangles;            // in the domain, all positive
  std::vector<std::vector<int>> loop_vertex;  // [loop][k]: vertex of loop point k
  // [loop][k]: Steiner vertices on loop edge k (point k -> k+1), in order from point k.
  std::vector<std::vector<std::vector<int>>> edge_chain;
};

// Errors: INVALID_ARGUMENT for loops with fewer than 3 points, constraints that cross (the
// loops are not a valid planar graph), INTERNAL if CGAL fails.
absl::StatusOr<DomainTriangulation> CgalTriangulateDomain(const std::vector<Points>& loops,
                                                          const TriangulateOptions& options = {});

}  // namespace inbetween::solver
