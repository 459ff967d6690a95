// Negative tests of the multimesh validators (solver/mesh/validate.h), the checks the server runs
// before it accepts a multimesh: valid multimeshes of two real examples (square_hexagon: one
// loop; split: a cut, two loops, cohesive pairs closed in drawing 1 only) pass, and each copy
// with one thing corrupted is rejected as INVALID_ARGUMENT with a message naming the shape,
// triangle, loop, vertex or cohesive edge at fault.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"
#include "tests/unit/solver/mesh/example_projects.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

// Built once per example.
const Multimesh& Example(const std::string& name) {
  static std::map<std::string, Multimesh>* cache = new std::map<std::string, Multimesh>;
  auto it = cache->find(name);
  if (it == cache->end()) {
    absl::StatusOr<example_projects::Example> example = example_projects::Load(name);
    EXPECT_TRUE(example.ok()) << example.status();
    absl::StatusOr<Multimesh> mesh = BuildMultimesh(example->drawings, example->options);
    EXPECT_TRUE(mesh.ok()) << name << ": " << mesh.status();
    it = cache->emplace(name, mesh.ok() ? *std::move(mesh) : Multimesh{}).first;
  }
  return it->second;
}

const Multimesh& SquareHexagon() { return Example("square_hexagon"); }
const Multimesh& Split() { return Example("split"); }

std::vector<bool> OnBoundary(const Multimesh& m) {
  std::vector<bool> on(m.num_vertices(), false);
  for (const auto& loop : m.boundary_loops) {
    for (int v : loop) on[v] = true;
  }
  return on;
}

// The first triangle with no vertex on the boundary.
int InteriorTriangle(const Multimesh& m) {
  const std::vector<bool> on = OnBoundary(m);
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const Triangle& tri = m.triangles[t];
    if (!on[tri[0]] && !on[tri[1]] && !on[tri[2]]) return static_cast<int>(t);
  }
  return -1;
}

// The shape in which the multimesh's cohesive pairs are closed (split: drawing 1, the whole cell)
// and one where they are open.
int ClosedShape(const Multimesh& m) {
  for (int s = 0; s < m.num_shapes(); ++s) {
    if (!m.cohesive_closed[s].empty()) return s;
  }
  return -1;
}
int OpenShape(const Multimesh& m) {
  for (int s = 0; s < m.num_shapes(); ++s) {
    if (m.cohesive_closed[s].empty()) return s;
  }
  return -1;
}

double Diagonal(const Points& x) {
  Point lo = x[0], hi = x[0];
  for (const Point& p : x) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return (hi - lo).norm();
}

// Every validator that should see `m` as broken says so with `message` (ValidateMultimesh runs
// the loop and cohesive checks too).
void ExpectRejected(const absl::Status& s, const std::string& message) {
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  EXPECT_THAT(std::string(s.message()), HasSubstr(message));
}

// ---- The uncorrupted multimeshes ----

TEST(ValidateRejectsTest, ExampleMultimeshesPass) {
  for (const Multimesh* m : {&SquareHexagon(), &Split()}) {
    ASSERT_EQ(m->num_shapes(), 2);
    ASSERT_FALSE(m->boundary_loops.empty());
    EXPECT_TRUE(ValidateMultimesh(*m).ok()) << ValidateMultimesh(*m);
    EXPECT_TRUE(ValidateBoundaryLoops(*m).ok()) << ValidateBoundaryLoops(*m);
    EXPECT_TRUE(ValidateCohesiveEdges(*m).ok()) << ValidateCohesiveEdges(*m);
    EXPECT_GE(InteriorTriangle(*m), 0);
  }
  EXPECT_TRUE(SquareHexagon().cohesive_edges.empty());
  ASSERT_FALSE(Split().cohesive_edges.empty());
  EXPECT_EQ(Split().boundary_loops.size(), 2u);
  EXPECT_EQ(ClosedShape(Split()), 0);  // the whole cell with its cut
  EXPECT_EQ(OpenShape(Split()), 1);    // the two cells apart
}

// ---- Shared topology ----

TEST(ValidateRejectsTest, NoShapes) {
  Multimesh m = SquareHexagon();
  m.shapes.clear();
  ExpectRejected(ValidateMultimesh(m), "multimesh has no shapes");
}

TEST(ValidateRejectsTest, MismatchedVertexCounts) {
  const int n = SquareHexagon().num_vertices();
  Multimesh m = SquareHexagon();
  m.shapes[1].pop_back();
  ExpectRejected(ValidateMultimesh(m),
                 absl::StrCat("multimesh shape 1 has ", n - 1, " vertices, shape 0 has ", n));
  m = SquareHexagon();
  m.shapes[1].push_back(m.shapes[1][0]);
  ExpectRejected(ValidateMultimesh(m), absl::StrCat("multimesh shape 1 has ", n + 1, " vertices"));
  // A third shape with another count.
  m = Split();
  m.shapes.push_back(Points(m.shapes[0].begin(), m.shapes[0].end() - 3));
  ExpectRejected(ValidateMultimesh(m),
                 absl::StrCat("multimesh shape 2 has ", Split().num_vertices() - 3, " vertices"));
}

TEST(ValidateRejectsTest, NonFiniteCoordinates) {
  const int v = SquareHexagon().num_vertices() / 2;
  Multimesh m = SquareHexagon();
  m.shapes[1][v].y() = std::numeric_limits<double>::quiet_NaN();
  ExpectRejected(ValidateMultimesh(m),
                 absl::StrCat("multimesh shape 1 vertex ", v, " is not finite"));
  m = SquareHexagon();
  m.shapes[0][3].x() = std::numeric_limits<double>::infinity();
  ExpectRejected(ValidateMultimesh(m), "multimesh shape 0 vertex 3 is not finite");
}

TEST(ValidateRejectsTest, TriangleIndexOutOfRange) {
  const int n = SquareHexagon().num_vertices();
  Multimesh m = SquareHexagon();
  m.triangles[7][1] = n;
  ExpectRejected(ValidateMultimesh(m), absl::StrCat("multimesh triangle 7 has vertex index ", n,
                                                    " out of range [0, ", n, ")"));
  m = SquareHexagon();
  m.triangles[2][0] = -1;
  ExpectRejected(ValidateMultimesh(m), "multimesh triangle 2 has vertex index -1 out of range");
}

TEST(ValidateRejectsTest, TriangleRepeatsAVertex) {
  Multimesh m = SquareHexagon();
  m.triangles[5][2] = m.triangles[5][0];
  ExpectRejected(ValidateMultimesh(m), "multimesh triangle 5 repeats a vertex");
}

TEST(ValidateRejectsTest, BoundaryIndexOutOfRange) {
  const int n = SquareHexagon().num_vertices();
  Multimesh m = SquareHexagon();
  m.boundary[3] = n + 5;
  ExpectRejected(ValidateMultimesh(m),
                 absl::StrCat("multimesh boundary vertex ", n + 5, " out of range [0, ", n, ")"));
  m = SquareHexagon();
  m.boundary[0] = -2;
  ExpectRejected(ValidateMultimesh(m), "multimesh boundary vertex -2 out of range");
}

TEST(ValidateRejectsTest, PinnedVerticesOutOfRangeOrUnordered) {
  const int n = SquareHexagon().num_vertices();
  Multimesh m = SquareHexagon();
  m.pinned = {1, 4};
  EXPECT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  m.pinned = {1, n};
  ExpectRejected(ValidateMultimesh(m),
                 absl::StrCat("multimesh pinned vertex ", n, " out of range [0, ", n, ")"));
  m.pinned = {4, 1};
  ExpectRejected(ValidateMultimesh(m), "multimesh pinned vertices are not ascending and distinct at 1");
  m.pinned = {4, 4};
  ExpectRejected(ValidateMultimesh(m), "not ascending and distinct at 4");
}

// The same triangle twice (or any two triangles on one directed edge) covers part of every shape
// twice: not one shared manifold topology, though every triangle is positive.
TEST(ValidateRejectsTest, DuplicateTriangle) {
  for (const Multimesh* original : {&SquareHexagon(), &Split()}) {
    const int t = InteriorTriangle(*original);
    const Triangle tri = original->triangles[t];
    const int last = static_cast<int>(original->triangles.size());
    for (bool with_loops : {true, false}) {  // without: as the server receives a multimesh
      Multimesh m = *original;
      if (!with_loops) m.boundary_loops.clear();
      m.triangles.push_back(tri);
      ExpectRejected(ValidateMultimesh(m),
                     absl::StrCat("multimesh triangles ", t, " and ", last, " both have edge "));
      // Rotated corners: the same triangle again.
      m.triangles.back() = {tri[1], tri[2], tri[0]};
      ExpectRejected(ValidateMultimesh(m), absl::StrCat("multimesh triangles ", t, " and ", last));
    }
  }
}

TEST(ValidateRejectsTest, TriangleOverlappingItsNeighbours) {
  // A new triangle on interior edge a-b (which already has its two triangles), positive in every
  // shape: it lies over triangle t, which has the same directed edge a-b. Also without the
  // boundary loops (a multimesh received by the server has none), where no loop count can show
  // the extra boundary edges it makes.
  for (bool with_loops : {true, false}) {
    Multimesh m = SquareHexagon();
    const int t = InteriorTriangle(m);
    if (!with_loops) m.boundary_loops.clear();
    const Triangle tri = m.triangles[t];
    // Its other two edges must be new, so that a-b is the edge the validator names (which
    // vertex comes first depends on the mesh).
    std::set<std::pair<int, int>> directed;
    for (const Triangle& u : m.triangles) {
      for (int k = 0; k < 3; ++k) directed.insert({u[k], u[(k + 1) % 3]});
    }
    int extra = -1;
    for (int c = 0; c < m.num_vertices() && extra < 0; ++c) {
      if (c == tri[0] || c == tri[1] || c == tri[2]) continue;
      if (directed.count({tri[1], c}) || directed.count({c, tri[0]})) continue;
      bool positive = true;
      for (const Points& x : m.shapes)
        positive = positive && SignedArea2({tri[0], tri[1], c}, x) > 0;
      if (positive) extra = c;
    }
    ASSERT_GE(extra, 0);
    m.triangles.push_back({tri[0], tri[1], extra});
    ExpectRejected(ValidateMultimesh(m),
                   absl::StrCat("multimesh triangles ", t, " and ", m.triangles.size() - 1,
                                " both have edge ", tri[0], "-", tri[1]));
  }
}

// ---- No inverted or degenerate triangle in any shape ----

TEST(ValidateRejectsTest, InvertedTriangle) {
  Multimesh m = SquareHexagon();
  const int t = InteriorTriangle(m);
  const auto [a, b, c] = m.triangles[t];
  // Reflect a across the line b-c in shape 1: triangle t is inverted there.
  Points& x = m.shapes[1];
  const Point d = (x[c] - x[b]).normalized();
  const Point foot = x[b] + (x[a] - x[b]).dot(d) * d;
  x[a] = 2 * foot - x[a];
  ASSERT_LT(SignedArea2(m.triangles[t], x), 0);
  int first = -1;  // the validator names the first bad triangle of the shape
  for (size_t i = 0; i < m.triangles.size() && first < 0; ++i) {
    if (!(SignedArea2(m.triangles[i], x) > 0)) first = static_cast<int>(i);
  }
  ASSERT_GE(first, 0);
  ExpectRejected(ValidateMultimesh(m),
                 absl::StrCat("multimesh shape 1 triangle ", first, " is inverted (signed area -"));
  EXPECT_TRUE(ValidateMultimesh(SquareHexagon()).ok());
  EXPECT_EQ(CountInverted(m.triangles, m.shapes[0]), 0);
  EXPECT_GE(CountInverted(m.triangles, m.shapes[1]), 1);
}

TEST(ValidateRejectsTest, DegenerateTriangle) {
  // Shape 1 flattened onto a line: every triangle has signed area exactly 0.
  Multimesh m = SquareHexagon();
  for (Point& p : m.shapes[1]) p.y() = 0;
  ExpectRejected(ValidateMultimesh(m),
                 "multimesh shape 1 triangle 0 is degenerate (signed area 0)");
  // One interior vertex moved onto a neighbour in shape 1: the triangles holding both are
  // degenerate (exactly zero area), whatever happens to the others first.
  m = SquareHexagon();
  const int t = InteriorTriangle(m);
  m.shapes[1][m.triangles[t][0]] = m.shapes[1][m.triangles[t][1]];
  EXPECT_EQ(SignedArea2(m.triangles[t], m.shapes[1]), 0.0);
  int first = -1;
  for (size_t i = 0; i < m.triangles.size() && first < 0; ++i) {
    if (!(SignedArea2(m.triangles[i], m.shapes[1]) > 0)) first = static_cast<int>(i);
  }
  const bool zero = SignedArea2(m.triangles[first], m.shapes[1]) == 0.0;
  ExpectRejected(ValidateMultimesh(m), absl::StrCat("multimesh shape 1 triangle ", first,
                                                    zero ? " is degenerate" : " is inverted"));
}

// ---- Boundary vertices on their boundaries ----

TEST(ValidateRejectsTest, BoundaryLoopVertexOutOfRange) {
  const int n = Split().num_vertices();
  Multimesh m = Split();
  m.boundary_loops[1][0] = n;
  for (const absl::Status& s : {ValidateBoundaryLoops(m), ValidateMultimesh(m)}) {
    ExpectRejected(s, absl::StrCat("multimesh boundary loop 1 vertex ", n, " out of range"));
  }
  m = Split();
  m.boundary_loops[0][0] = -1;
  ExpectRejected(ValidateBoundaryLoops(m), "multimesh boundary loop 0 vertex -1 out of range");
}

TEST(ValidateRejectsTest, BoundaryLoopVertexOffTheBoundary) {
  Multimesh m = SquareHexagon();
  const int interior = m.triangles[InteriorTriangle(m)][0];
  std::vector<int>& loop = m.boundary_loops[0];
  const int prev = loop[4];
  loop[5] = interior;
  for (const absl::Status& s : {ValidateBoundaryLoops(m), ValidateMultimesh(m)}) {
    ExpectRejected(s, absl::StrCat("multimesh boundary loop 0: edge ", prev, "-", interior,
                                   " is not a boundary edge"));
  }
}

TEST(ValidateRejectsTest, BoundaryLoopReversed) {
  Multimesh m = Split();
  std::vector<int>& loop = m.boundary_loops[1];
  std::reverse(loop.begin(), loop.end());  // the mesh on the right of every edge
  for (const absl::Status& s : {ValidateBoundaryLoops(m), ValidateMultimesh(m)}) {
    ExpectRejected(s, absl::StrCat("multimesh boundary loop 1: edge ", loop[0], "-", loop[1],
                                   " is not a boundary edge"));
  }
}

TEST(ValidateRejectsTest, BoundaryLoopSkipsAVertex) {
  Multimesh m = SquareHexagon();
  std::vector<int>& loop = m.boundary_loops[0];
  const int a = loop[2], c = loop[4];
  loop.erase(loop.begin() + 3);
  ExpectRejected(ValidateBoundaryLoops(m), absl::StrCat("multimesh boundary loop 0: edge ", a, "-",
                                                        c, " is not a boundary edge"));
}

TEST(ValidateRejectsTest, BoundaryLoopMissingOrRepeated) {
  const Multimesh& split = Split();
  const size_t edges = split.boundary_loops[0].size() + split.boundary_loops[1].size();
  Multimesh m = split;
  m.boundary_loops.pop_back();
  for (const absl::Status& s : {ValidateBoundaryLoops(m), ValidateMultimesh(m)}) {
    ExpectRejected(s, absl::StrCat("multimesh has ", edges, " boundary edges but its loops list ",
                                   split.boundary_loops[0].size()));
  }
  // Loop 0 twice, loop 1 missing: when both loops have the same length only the repetition shows.
  m = split;
  m.boundary_loops[1] = m.boundary_loops[0];
  ExpectRejected(ValidateBoundaryLoops(m), "multimesh boundary loop 1: edge ");
  ExpectRejected(ValidateBoundaryLoops(m), "is listed twice");
  // A loop walked twice round.
  m = SquareHexagon();
  std::vector<int>& loop = m.boundary_loops[0];
  const std::vector<int> once = loop;
  loop.insert(loop.end(), once.begin(), once.end());
  ExpectRejected(ValidateBoundaryLoops(m), "is listed twice");
}

// `boundary` (boundary vertices in boundary order, the loops' concatenation) must hold boundary
// vertices; the server receives only it (no loops) with an imported multimesh.
TEST(ValidateRejectsTest, BoundaryListHoldsAnInteriorVertex) {
  for (bool with_loops : {true, false}) {
    Multimesh m = SquareHexagon();
    const int interior = m.triangles[InteriorTriangle(m)][0];
    if (!with_loops) m.boundary_loops.clear();
    m.boundary[6] = interior;
    ExpectRejected(ValidateMultimesh(m), absl::StrCat("multimesh boundary vertex ", interior,
                                                      " (boundary[6]) is not on the boundary"));
  }
}

TEST(ValidateRejectsTest, BoundaryListDisagreesWithTheLoops) {
  Multimesh m = Split();
  std::rotate(m.boundary.begin(), m.boundary.begin() + 1, m.boundary.end());
  ExpectRejected(ValidateMultimesh(m), "multimesh boundary is not the concatenation of its loops");
  m = Split();
  m.boundary.pop_back();
  ExpectRejected(ValidateMultimesh(m), "multimesh boundary is not the concatenation of its loops");
}

// ---- Cohesive pairs collocated where closed ----

TEST(ValidateRejectsTest, CohesiveVertexOutOfRange) {
  const int n = Split().num_vertices();
  Multimesh m = Split();
  m.cohesive_edges[2][3] = n + 1;
  for (const absl::Status& s : {ValidateCohesiveEdges(m), ValidateMultimesh(m)}) {
    ExpectRejected(s, absl::StrCat("multimesh cohesive edge 2 vertex ", n + 1, " out of range"));
  }
  m = Split();
  m.cohesive_edges[0][0] = -1;
  ExpectRejected(ValidateCohesiveEdges(m), "multimesh cohesive edge 0 vertex -1 out of range");
}

TEST(ValidateRejectsTest, CohesiveClosedListsMalformed) {
  Multimesh m = Split();
  m.cohesive_closed.pop_back();
  ExpectRejected(ValidateCohesiveEdges(m), "multimesh cohesive_closed needs one list per shape");
  m = Split();
  const int count = static_cast<int>(m.cohesive_edges.size());
  m.cohesive_closed[1].push_back(count);
  for (const absl::Status& s : {ValidateCohesiveEdges(m), ValidateMultimesh(m)}) {
    ExpectRejected(s,
                   absl::StrCat("multimesh shape 1 lists cohesive edge ", count, " out of range"));
  }
  m = Split();
  m.cohesive_closed[0][0] = -3;
  ExpectRejected(ValidateCohesiveEdges(m), "multimesh shape 0 lists cohesive edge -3 out of range");
}

TEST(ValidateRejectsTest, CohesiveSidesApartWhereClosed) {
  Multimesh m = Split();
  const int s = ClosedShape(m);
  const int c = m.cohesive_closed[s][m.cohesive_closed[s].size() / 2];
  const int a = m.cohesive_edges[c][0];
  // A tiny move (well above the 1e-9 relative tolerance, far too small to fold a triangle).
  const double shift = 1e-6 * Diagonal(m.shapes[s]);
  m.shapes[s][a] += Point(shift, 0);
  ASSERT_EQ(CountInverted(m.triangles, m.shapes[s]), 0);
  int first = -1;  // the first closed pair holding a
  for (int k : m.cohesive_closed[s]) {
    const auto& e = m.cohesive_edges[k];
    if (first < 0 && std::count(e.begin(), e.end(), a) > 0) first = k;
  }
  for (const absl::Status& st : {ValidateCohesiveEdges(m), ValidateMultimesh(m)}) {
    ExpectRejected(st, absl::StrCat("multimesh shape ", s, ": cohesive edge ", first,
                                    " is closed there but its sides are "));
  }
  // The same move in the shape where the cut is open is fine.
  m = Split();
  m.shapes[OpenShape(m)][a] += Point(1e-6 * Diagonal(m.shapes[OpenShape(m)]), 0);
  EXPECT_TRUE(ValidateCohesiveEdges(m).ok()) << ValidateCohesiveEdges(m);
}

TEST(ValidateRejectsTest, CohesivePairClaimedClosedWhereOpen) {
  Multimesh m = Split();
  const int s = OpenShape(m);
  m.cohesive_closed[s].push_back(1);
  for (const absl::Status& st : {ValidateCohesiveEdges(m), ValidateMultimesh(m)}) {
    ExpectRejected(st, absl::StrCat("multimesh shape ", s,
                                    ": cohesive edge 1 is closed there but its sides are "));
  }
}

TEST(ValidateRejectsTest, CohesivePairMatchedTheWrongWayRound) {
  // {a, b, c, d}: a with c, b with d. Pairing a with d instead is not collocated.
  Multimesh m = Split();
  const int s = ClosedShape(m);
  const int c = m.cohesive_closed[s][0];
  std::swap(m.cohesive_edges[c][2], m.cohesive_edges[c][3]);
  ExpectRejected(ValidateCohesiveEdges(m),
                 absl::StrCat("multimesh shape ", s, ": cohesive edge ", c, " is closed there"));
}

TEST(ValidateRejectsTest, CohesiveVertexNotFiniteWhereClosed) {
  // On its own (ValidateMultimesh rejects non-finite coordinates first).
  Multimesh m = Split();
  const int s = ClosedShape(m);
  const int c = m.cohesive_closed[s][0];
  m.shapes[s][m.cohesive_edges[c][1]].x() = std::numeric_limits<double>::quiet_NaN();
  ExpectRejected(ValidateCohesiveEdges(m),
                 absl::StrCat("multimesh shape ", s, ": cohesive edge ", c, " is closed there"));
}

}  // namespace
}  // namespace inbetween::solver
