// Tests of CollapseVertices (collapse_vertices.h): removable vertices that only add thin
// triangles merge away in every shape at once, nothing inverts, the other vertices stay.
#include "solver/mesh/collapse_vertices.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

double Area(const std::vector<Triangle>& triangles, const Points& x) {
  double a = 0;
  for (const Triangle& t : triangles) a += 0.5 * SignedArea2(t, x);
  return a;
}

double Worst(const std::vector<Triangle>& triangles, const std::vector<Points>& shapes) {
  double worst = INFINITY;
  for (const Points& s : shapes) worst = std::min(worst, WorstTriangleQuality(triangles, s));
  return worst;
}

// Triangles as sets of corners rotated to start at the smallest index (orientation kept).
std::set<Triangle> Canonical(const std::vector<Triangle>& triangles) {
  std::set<Triangle> out;
  for (Triangle t : triangles) {
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.insert(t);
  }
  return out;
}

// A swirl about (50, 50): smooth, orientation-preserving for small angles, so a mesh of the
// disk stays valid in it and its triangles change shape unevenly.
Point Swirl(const Point& p) {
  const Point d = p - Point(50, 50);
  const double a = 0.6 * std::exp(-d.squaredNorm() / 1500.0);
  return Point(50 + std::cos(a) * d.x() - std::sin(a) * d.y(),
               50 + std::sin(a) * d.x() + std::cos(a) * d.y());
}

// A mesh of a disk in two shapes (the second swirled), then interior edges split close to one end
// (slivers in both shapes), no two split edges on the same triangle.
struct SplitMesh {
  std::vector<Triangle> original, triangles;
  std::vector<Points> shapes;
  int n = 0, splits = 0;
};

SplitMesh MakeSplitMesh() {
  Points circle;
  for (int k = 0; k < 40; ++k) {
    circle.emplace_back(50 + 40 * std::cos(2 * M_PI * k / 40),
                        50 + 40 * std::sin(2 * M_PI * k / 40));
  }
  TriangulateOptions options;
  options.max_edge = 8;
  absl::StatusOr<PolygonTriangulation> disk = CgalTriangulate(circle, options);
  EXPECT_TRUE(disk.ok()) << disk.status();
  SplitMesh m;
  m.original = m.triangles = disk->triangles;
  m.n = static_cast<int>(disk->vertices.size());
  Points swirled;
  for (const Point& p : disk->vertices) swirled.push_back(Swirl(p));
  m.shapes = {disk->vertices, swirled};
  std::vector<bool> used(m.triangles.size(), false);
  for (size_t t = 0; t < m.original.size(); ++t) {
    for (int k = 0; k < 3 && !used[t]; ++k) {
      const int a = m.original[t][k], b = m.original[t][(k + 1) % 3];
      // The triangle across edge (a, b): it holds b -> a.
      size_t u = 0;
      for (; u < m.original.size(); ++u) {
        const Triangle& o = m.original[u];
        bool across = false;
        for (int j = 0; j < 3; ++j) across |= o[j] == b && o[(j + 1) % 3] == a;
        if (across) break;
      }
      if (u == m.original.size() || used[u]) continue;  // a boundary edge, or taken
      used[t] = used[u] = true;
      const int v = static_cast<int>(m.shapes[0].size());
      const double s = (m.splits % 2 == 0) ? 0.03 : 0.97;  // near a, or near b
      for (Points& x : m.shapes) x.push_back((1 - s) * x[a] + s * x[b]);
      const int c = m.original[t][(k + 2) % 3];
      int d = -1;
      for (int j = 0; j < 3; ++j) {
        if (m.original[u][j] != a && m.original[u][j] != b) d = m.original[u][j];
      }
      m.triangles[t] = {a, v, c};
      m.triangles[u] = {b, v, d};
      m.triangles.push_back({v, b, c});
      m.triangles.push_back({v, a, d});
      ++m.splits;
    }
  }
  return m;
}

TEST(CollapseVerticesTest, SplitSliversMergeBackInEveryShape) {
  const SplitMesh m = MakeSplitMesh();
  ASSERT_GT(m.splits, 20);
  for (const Points& s : m.shapes) ASSERT_EQ(CountInverted(m.triangles, s), 0);
  const double worst_before = Worst(m.triangles, m.shapes);
  EXPECT_LT(worst_before, 0.1);  // the splits made slivers

  absl::StatusOr<CollapseResult> r = CollapseVertices(m.triangles, m.shapes, m.n);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->removed, m.splits);
  ASSERT_EQ(r->shapes.size(), 2u);
  // Merging a split vertex into either end of its edge gives the two original triangles back,
  // into either opposite corner the two across the other diagonal: whichever is better wins, so
  // the result is as good as the unsplit mesh at least, with its triangle count.
  EXPECT_EQ(r->triangles.size(), m.original.size());
  EXPECT_GE(Worst(r->triangles, r->shapes), Worst(m.original, {m.shapes[0], m.shapes[1]}));
  size_t kept = 0;  // most quadrilaterals keep their diagonal (Delaunay: usually the better one)
  const std::set<Triangle> original = Canonical(m.original);
  for (const Triangle& t : Canonical(r->triangles)) kept += original.count(t);
  EXPECT_GT(kept, m.original.size() / 2);
  for (int v = 0; v < m.n; ++v) {
    EXPECT_EQ(r->old_to_new[v], v);
    EXPECT_EQ(r->shapes[0][v], m.shapes[0][v]);
    EXPECT_EQ(r->shapes[1][v], m.shapes[1][v]);
  }
  for (int v = m.n; v < static_cast<int>(m.shapes[0].size()); ++v) EXPECT_EQ(r->old_to_new[v], -1);
  EXPECT_GT(Worst(r->triangles, r->shapes), worst_before);
}

TEST(CollapseVerticesTest, OnlyRemovableInteriorVerticesGoAndNothingGetsWorse) {
  const SplitMesh m = MakeSplitMesh();
  // Everything removable: the disk's own interior vertices may go too, never a boundary one,
  // and never so that the worst triangle in any shape gets thinner.
  for (double floor : {0.0, 0.3}) {
    absl::StatusOr<CollapseResult> r =
        CollapseVertices(m.triangles, m.shapes, 0, CollapseOptions{.quality_floor = floor});
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_GE(r->removed, m.splits);
    Multimesh mesh;
    mesh.triangles = r->triangles;
    mesh.shapes = r->shapes;
    for (int v = 0; v < 40; ++v) {  // the circle's points: the boundary, in order
      ASSERT_GE(r->old_to_new[v], 0) << v;
      mesh.boundary.push_back(r->old_to_new[v]);
    }
    mesh.boundary_loops = {mesh.boundary};
    EXPECT_TRUE(ValidateMultimesh(mesh).ok()) << ValidateMultimesh(mesh);
    for (size_t s = 0; s < m.shapes.size(); ++s) {
      EXPECT_NEAR(Area(r->triangles, r->shapes[s]), Area(m.triangles, m.shapes[s]), 1e-6);
    }
    EXPECT_GE(Worst(r->triangles, r->shapes), std::min(Worst(m.triangles, m.shapes), floor));
  }
  // A floor trades quality for vertices: at least as many go as without one.
  absl::StatusOr<CollapseResult> strict = CollapseVertices(m.triangles, m.shapes, 0);
  absl::StatusOr<CollapseResult> loose =
      CollapseVertices(m.triangles, m.shapes, 0, CollapseOptions{.quality_floor = 0.3});
  ASSERT_TRUE(strict.ok() && loose.ok());
  EXPECT_GT(loose->removed, strict->removed);
}

TEST(CollapseVerticesTest, AVertexWhoseMergeWouldFoldInAnotherShapeStays) {
  // Vertex 4 inside the quadrilateral 0 (a), 1 (c), 2 (b), 3 (d). In shape 1 the quadrilateral is
  // reflex at a: merging 4 into a or b is fine (diagonal a-b), into c or d folds. Shape 2 places
  // the same four points one step round, reflex at c: only c and d would do there.
  const std::vector<Triangle> triangles = {{4, 0, 1}, {4, 1, 2}, {4, 2, 3}, {4, 3, 0}};
  const Point p1(-0.3, 0), p2(-0.5, -1), p3(1, 0), p4(-0.5, 1), v(0, 0);
  const Points first = {p1, p2, p3, p4, v};
  const Points second = {p4, p1, p2, p3, v};
  for (const Points& s : {first, second}) ASSERT_EQ(CountInverted(triangles, s), 0);
  for (const Points& s : {first, second}) {
    absl::StatusOr<CollapseResult> alone = CollapseVertices(triangles, {s}, 4);
    ASSERT_TRUE(alone.ok()) << alone.status();
    EXPECT_EQ(alone->removed, 1);
    EXPECT_EQ(alone->triangles.size(), 2u);
    EXPECT_EQ(CountInverted(alone->triangles, alone->shapes[0]), 0);
  }
  absl::StatusOr<CollapseResult> both = CollapseVertices(triangles, {first, second}, 4);
  ASSERT_TRUE(both.ok()) << both.status();
  EXPECT_EQ(both->removed, 0);
  EXPECT_EQ(both->triangles, triangles);
}

TEST(CollapseVerticesTest, BadInputsAndCancellation) {
  const std::vector<Triangle> triangles = {{0, 1, 2}};
  const Points p = {{0, 0}, {1, 0}, {0, 1}};
  EXPECT_EQ(CollapseVertices(triangles, {}, 0).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CollapseVertices(triangles, {p, {{0, 0}}}, 0).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CollapseVertices({{0, 1, 3}}, {p}, 0).status().code(),
            absl::StatusCode::kInvalidArgument);
  CancelToken cancel;
  cancel.Cancel();
  EXPECT_EQ(CollapseVertices(triangles, {p}, 0, {}, &cancel).status().code(),
            absl::StatusCode::kCancelled);
  absl::StatusOr<CollapseResult> none = CollapseVertices(triangles, {p}, 0);
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->removed, 0);  // no interior vertex
}

}  // namespace
}  // namespace inbetween::solver
