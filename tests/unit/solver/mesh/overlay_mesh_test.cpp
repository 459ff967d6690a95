// Tests of the overlay (overlay_mesh.h): a mesh that cannot be mapped into a drawing is refined
// into one that maps into both without folding, the old vertices kept where they were.
#include "solver/mesh/overlay_mesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "solver/geometry/polygon.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/collapse_vertices.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

// A comb with `teeth` teeth, `points` boundary points in all, counter-clockwise from (0, 0).
Points Comb(int teeth) {
  Points p = {{0, 0}, {100, 0}};
  const double w = 100.0 / (2 * teeth - 1);
  for (int t = teeth - 1; t >= 0; --t) {
    const double x0 = 2 * t * w;
    p.emplace_back(x0 + w, 100);
    p.emplace_back(x0, 100);
    if (t > 0) p.emplace_back(x0, 20), p.emplace_back(x0 - w, 20);
  }
  // The last tooth ends at (0, 100); the comb closes back down to (0, 0).
  Points out;
  for (const Point& q : p) {
    if (out.empty() || (q - out.back()).norm() > 0) out.push_back(q);
  }
  return out;
}

// `n` points around a circle of radius r centred at (50, 50), counter-clockwise.
Points Circle(int n, double r) {
  Points p;
  for (int k = 0; k < n; ++k) {
    p.emplace_back(50 + r * std::cos(2 * M_PI * k / n), 50 + r * std::sin(2 * M_PI * k / n));
  }
  return p;
}

double Area(const std::vector<Triangle>& triangles, const Points& x) {
  double a = 0;
  for (const Triangle& t : triangles) a += 0.5 * SignedArea2(t, x);
  return a;
}

// Distance from p to the nearest edge of the mesh (every triangle side).
double DistanceToEdges(const std::vector<Triangle>& triangles, const Points& x, const Point& p) {
  double best = INFINITY;
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      best = std::min(best, DistanceToSegment(p, x[t[k]], x[t[(k + 1) % 3]]));
    }
  }
  return best;
}

// The comb's boundary points, placed in order around a disk: the disk's Delaunay mesh cannot be
// pulled onto the comb's deep teeth without folding in general, and the overlay maps it.
TEST(OverlayMeshTest, DiskMeshOntoAComb) {
  const Points comb = Comb(4);
  const int corners = static_cast<int>(comb.size());
  TriangulateOptions options;
  options.max_edge = 12;
  absl::StatusOr<PolygonTriangulation> disk = CgalTriangulate(Circle(corners, 50), options);
  ASSERT_TRUE(disk.ok()) << disk.status();
  // The boundary in order (the mesher's boundary points after their segment's start), and the
  // comb's points at the same segment parameters.
  std::vector<int> boundary;
  Points target;
  for (int k = 0, next = 0; k < corners; ++k) {
    boundary.push_back(k);
    target.push_back(comb[k]);
    for (; next < static_cast<int>(disk->boundary_steiner.size()) &&
           disk->boundary_steiner[next].segment == k;
         ++next) {
      const BoundarySteiner& b = disk->boundary_steiner[next];
      boundary.push_back(b.vertex);
      target.push_back((1 - b.t) * comb[k] + b.t * comb[(k + 1) % corners]);
    }
  }
  const int nb = static_cast<int>(boundary.size());
  const Points& comb_points = target;
  const int n = static_cast<int>(disk->vertices.size());

  absl::StatusOr<OverlayResult> over =
      OverlayOntoPolygon(disk->triangles, {disk->vertices}, boundary, comb_points);
  ASSERT_TRUE(over.ok()) << over.status();
  ASSERT_EQ(over->shapes.size(), 2u);
  const int total = n + over->added_vertices;
  EXPECT_GT(over->added_vertices, 0);
  for (const Points& s : over->shapes) {
    ASSERT_EQ(static_cast<int>(s.size()), total);
    EXPECT_EQ(CountInverted(over->triangles, s), 0);
  }
  // Every vertex is used and the old ones keep their places in the first shape; the new ones
  // lie on the old mesh's edges there (a refinement), and the areas are the polygons'.
  std::vector<int> uses(total, 0);
  for (const Triangle& t : over->triangles)
    for (int v : t) ++uses[v];
  EXPECT_EQ(std::count(uses.begin(), uses.end(), 0), 0);
  for (int v = 0; v < n; ++v) EXPECT_EQ(over->shapes[0][v], disk->vertices[v]);
  for (int v = n; v < total; ++v) {
    EXPECT_LT(DistanceToEdges(disk->triangles, disk->vertices, over->shapes[0][v]), 1e-9);
  }
  EXPECT_NEAR(Area(over->triangles, over->shapes[0]), Area(disk->triangles, disk->vertices), 1e-6);
  EXPECT_NEAR(Area(over->triangles, over->shapes[1]), PolygonSignedArea(comb), 1e-6);
  for (int k = 0; k < nb; ++k) EXPECT_EQ(over->shapes[1][boundary[k]], comb_points[k]);
  // A valid multimesh: one loop, the same topology in both shapes.
  Multimesh mesh;
  mesh.triangles = over->triangles;
  mesh.shapes = over->shapes;
  mesh.boundary = boundary;
  mesh.boundary_loops = {boundary};
  EXPECT_TRUE(ValidateMultimesh(mesh).ok()) << ValidateMultimesh(mesh);
  // Crossings that a merge would take without thinning any drawing's triangles are gone.
  absl::StatusOr<CollapseResult> again = CollapseVertices(over->triangles, over->shapes, n);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(again->removed, 0);
  // A vertex bound below what the refinement needs stops it.
  absl::StatusOr<OverlayResult> bounded =
      OverlayOntoPolygon(disk->triangles, {disk->vertices}, boundary, comb_points, nullptr, n + 1);
  EXPECT_EQ(bounded.status().code(), absl::StatusCode::kResourceExhausted) << bounded.status();
  EXPECT_THAT(bounded.status().message(), HasSubstr("more than"));
}

// Shapes already placed (here a second copy, moved) get the new vertices through the same
// affine maps; a symmetric case (a fan around the centre, a square target whose diagonal may
// pass through it) stays valid.
TEST(OverlayMeshTest, EveryPlacedShapeIsRefinedAlike) {
  const Points square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  Points fan = square;
  fan.emplace_back(5, 5);
  const std::vector<Triangle> triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  Points moved = fan;
  for (Point& p : moved) p = Point(2 * p.x() + 3, p.y() - 1);
  const Points target = {{0, 0}, {10, 0}, {1, 1}, {0, 10}};  // concave at the third point
  absl::StatusOr<OverlayResult> over =
      OverlayOntoPolygon(triangles, {fan, moved}, {0, 1, 2, 3}, target);
  ASSERT_TRUE(over.ok()) << over.status();
  ASSERT_EQ(over->shapes.size(), 3u);
  for (const Points& s : over->shapes) EXPECT_EQ(CountInverted(over->triangles, s), 0);
  for (size_t v = 0; v < over->shapes[0].size(); ++v) {
    const Point p = over->shapes[0][v];
    EXPECT_LT((over->shapes[1][v] - Point(2 * p.x() + 3, p.y() - 1)).norm(), 1e-9);
  }
  EXPECT_NEAR(Area(over->triangles, over->shapes[2]), PolygonSignedArea(target), 1e-9);
}

TEST(OverlayMeshTest, ChordTriangulationAddsNoPoint) {
  const Points comb = Comb(3);
  TriangulateOptions options;
  options.refine = false;
  absl::StatusOr<PolygonTriangulation> cdt = CgalTriangulate(comb, options);
  ASSERT_TRUE(cdt.ok()) << cdt.status();
  EXPECT_EQ(cdt->vertices.size(), comb.size());
  EXPECT_EQ(cdt->triangles.size(), comb.size() - 2);
  EXPECT_EQ(CountInverted(cdt->triangles, cdt->vertices), 0);
}

// A square loop of side `side` centred at c, counter-clockwise (clockwise: a hole's order).
Points Square(const Point& c, double side, bool clockwise) {
  const double h = side / 2;
  Points p = {c + Point(-h, -h), c + Point(h, -h), c + Point(h, h), c + Point(-h, h)};
  if (clockwise) std::reverse(p.begin(), p.end());
  return p;
}

// A mesh of the domain `loops` bound (CgalTriangulateDomain), its boundary loops with the
// mesher's points on them, and those loops placed onto `targets` (the same number of corners
// per loop) at the same edge parameters.
struct DomainCase {
  DomainTriangulation mesh;
  std::vector<std::vector<int>> loops;
  std::vector<Points> targets;
};

DomainCase MeshDomain(const std::vector<Points>& loops, const std::vector<Points>& targets,
                      double max_edge, bool refine = true) {
  TriangulateOptions options;
  options.max_edge = max_edge;
  options.refine = refine;
  absl::StatusOr<DomainTriangulation> mesh = CgalTriangulateDomain(loops, options);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  // Without the points the mesher put inside the holes (no triangle uses them).
  std::vector<int> index(mesh->vertices.size(), -1);
  Points used;
  for (Triangle& t : mesh->triangles) {
    for (int& v : t) {
      if (index[v] < 0) index[v] = static_cast<int>(used.size()), used.push_back(mesh->vertices[v]);
      v = index[v];
    }
  }
  for (auto& loop : mesh->loop_vertex)
    for (int& v : loop) v = index[v];
  for (auto& loop : mesh->edge_chain)
    for (auto& chain : loop)
      for (int& v : chain) v = index[v];
  mesh->vertices = used;
  DomainCase c{*mesh, {}, {}};
  for (size_t l = 0; l < loops.size(); ++l) {
    std::vector<int> loop;
    Points target;
    const size_t m = loops[l].size();
    for (size_t k = 0; k < m; ++k) {
      const Point a = loops[l][k], b = loops[l][(k + 1) % m];
      const Point ta = targets[l][k], tb = targets[l][(k + 1) % m];
      loop.push_back(c.mesh.loop_vertex[l][k]);
      target.push_back(ta);
      for (int v : c.mesh.edge_chain[l][k]) {
        const double t = (c.mesh.vertices[v] - a).norm() / (b - a).norm();
        loop.push_back(v);
        target.push_back((1 - t) * ta + t * tb);
      }
    }
    c.loops.push_back(loop);
    c.targets.push_back(target);
  }
  return c;
}

// Overlays case c and checks the result: new vertices, valid in every drawing, the input
// vertices kept where they were in the first, the loops on their targets, the areas the
// domains', one multimesh.
void ExpectValidDomainOverlay(const DomainCase& c, double target_area) {
  absl::StatusOr<OverlayResult> overlaid =
      OverlayOntoDomain(c.mesh.triangles, {c.mesh.vertices}, c.loops, c.targets);
  ASSERT_TRUE(overlaid.ok()) << overlaid.status();
  const OverlayResult& over = *overlaid;
  EXPECT_GT(over.added_vertices, 0);
  const int n = static_cast<int>(c.mesh.vertices.size());
  ASSERT_EQ(over.shapes.size(), 2u);
  const int total = n + over.added_vertices;
  for (const Points& s : over.shapes) {
    ASSERT_EQ(static_cast<int>(s.size()), total);
    EXPECT_EQ(CountInverted(over.triangles, s), 0);
  }
  for (int v = 0; v < n; ++v) EXPECT_EQ(over.shapes[0][v], c.mesh.vertices[v]);
  EXPECT_NEAR(Area(over.triangles, over.shapes[0]), Area(c.mesh.triangles, c.mesh.vertices), 1e-6);
  EXPECT_NEAR(Area(over.triangles, over.shapes[1]), target_area, 1e-6);
  Multimesh mesh;
  mesh.triangles = over.triangles;
  mesh.shapes = over.shapes;
  for (size_t l = 0; l < c.loops.size(); ++l) {
    for (size_t k = 0; k < c.loops[l].size(); ++k) {
      EXPECT_EQ(over.shapes[1][c.loops[l][k]], c.targets[l][k]);
    }
    mesh.boundary.insert(mesh.boundary.end(), c.loops[l].begin(), c.loops[l].end());
    mesh.boundary_loops.push_back(c.loops[l]);
  }
  EXPECT_TRUE(ValidateMultimesh(mesh).ok()) << ValidateMultimesh(mesh);
}

// A square with a hole in the middle onto a comb whose hole sits in its first tooth: the mesh is
// cut open from the hole to the outline, overlaid, and glued back.
TEST(OverlayMeshTest, MeshWithAHoleOntoADrawingWhoseHoleMoved) {
  const Points comb = Comb(2);  // 8 corners: (0,0) (100,0) (100,100) (66.7,100) ...
  Points outer;  // a square with the comb's corner count, its points spread along the sides
  for (int k = 0; k < static_cast<int>(comb.size()); ++k) {
    const double a = 2 * M_PI * (k + 0.5) / comb.size() - 0.75 * M_PI;
    const double r = 50 / std::max(std::abs(std::cos(a)), std::abs(std::sin(a)));
    outer.emplace_back(50 + r * std::cos(a), 50 + r * std::sin(a));
  }
  const Points hole = Square({50, 50}, 20, true);
  const Points moved_hole = Square({16, 70}, 12, true);  // inside the comb's left tooth
  const DomainCase c = MeshDomain({outer, hole}, {comb, moved_hole}, 8);
  ExpectValidDomainOverlay(c, PolygonSignedArea(comb) + PolygonSignedArea(moved_hole));
}

// Three holes, each cut to the rest along its own path; the holes trade places.
TEST(OverlayMeshTest, EveryHoleIsCutOpenAndGluedBack) {
  const Points outer = Square({50, 50}, 100, false);
  const std::vector<Point> at = {{25, 25}, {75, 30}, {50, 75}};
  std::vector<Points> loops = {outer}, targets = {outer};
  for (int h = 0; h < 3; ++h) {
    loops.push_back(Square(at[h], 14, true));
    targets.push_back(Square(at[(h + 1) % 3], 10, true));
  }
  const DomainCase c = MeshDomain(loops, targets, 10);
  ExpectValidDomainOverlay(c, 100 * 100 - 3 * 10 * 10);
}

// An octagonal ring meshed without interior points: no path of interior vertices joins the
// loops, and in the new drawing the hole's points are turned half way round, so no edge of the mesh
// joins two points that an edge of the new drawing's triangulation joins: the cut needs the
// edges between boundary vertices split first.
TEST(OverlayMeshTest, CutsFindTheirWayWhereNoInteriorVertexSeparatesTheLoops) {
  const Points outer = Circle(8, 50);
  Points hole = Circle(8, 20);
  std::reverse(hole.begin(), hole.end());
  Points turned(8);
  for (int k = 0; k < 8; ++k) turned[k] = hole[(k + 4) % 8];
  const DomainCase c = MeshDomain({outer, hole}, {outer, turned}, 0, /*refine=*/false);
  ASSERT_EQ(c.mesh.vertices.size(), 16u);
  ExpectValidDomainOverlay(c, PolygonSignedArea(outer) + PolygonSignedArea(hole));
}

// A drawing whose outline is cut shut (a slit walked both ways, its two sides on the same
// points) is triangulated on both sides of the slit.
TEST(OverlayMeshTest, ClosedCutInTheNewDrawing) {
  // The source: a square with a notch (two sides of a cut, apart); the target: the notch shut.
  const Points notched = {{0, 0}, {40, 0}, {50, 30}, {60, 0}, {100, 0}, {100, 100}, {0, 100}};
  const Points shut = {{0, 0}, {50, 0}, {50, 30}, {50, 0}, {100, 0}, {100, 100}, {0, 100}};
  const DomainCase c = MeshDomain({notched}, {shut}, 12);
  absl::StatusOr<OverlayResult> over =
      OverlayOntoDomain(c.mesh.triangles, {c.mesh.vertices}, c.loops, c.targets);
  ASSERT_TRUE(over.ok()) << over.status();
  const int n = static_cast<int>(c.mesh.vertices.size());
  for (const Points& s : over->shapes) EXPECT_EQ(CountInverted(over->triangles, s), 0);
  for (int v = 0; v < n; ++v) EXPECT_EQ(over->shapes[0][v], c.mesh.vertices[v]);
  EXPECT_NEAR(Area(over->triangles, over->shapes[1]), 100 * 100, 1e-6);
}

TEST(OverlayMeshTest, BadInputsAreNamed) {
  const Points square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const std::vector<Triangle> triangles = {{0, 1, 2}, {0, 2, 3}};
  absl::StatusOr<OverlayResult> short_target =
      OverlayOntoPolygon(triangles, {square}, {0, 1, 2, 3}, {{0, 0}, {1, 0}, {1, 1}});
  EXPECT_EQ(short_target.status().code(), absl::StatusCode::kInvalidArgument);
  absl::StatusOr<OverlayResult> clockwise =
      OverlayOntoPolygon(triangles, {square}, {0, 1, 2, 3}, {{0, 0}, {0, 10}, {10, 10}, {10, 0}});
  EXPECT_EQ(clockwise.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(clockwise.status().message(), HasSubstr("overlay"));
  // Two loops no path of the mesh joins (two separate squares): the error says where the loop
  // left over lies.
  Points two = square;
  for (const Point& p : square) two.push_back(p + Point(20, 0));
  const std::vector<Triangle> apart = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  const Points moved = {{20, 0}, {30, 0}, {30, 10}, {20, 10}};
  absl::StatusOr<OverlayResult> no_cut =
      OverlayOntoDomain(apart, {two}, {{0, 1, 2, 3}, {4, 5, 6, 7}}, {square, moved});
  EXPECT_EQ(no_cut.status().code(), absl::StatusCode::kFailedPrecondition) << no_cut.status();
  EXPECT_THAT(no_cut.status().message(),
              HasSubstr("no cut through the mesh joins the boundary loop through (20, 0)"));
  CancelToken cancel;
  cancel.Cancel();
  absl::StatusOr<OverlayResult> cancelled =
      OverlayOntoPolygon(triangles, {square}, {0, 1, 2, 3}, square, &cancel);
  EXPECT_EQ(cancelled.status().code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace inbetween::solver
