// Tests for the comesh outer loop's topology pass: flips and collapses valid in every shape,
// objective never increases, boundary and cohesive vertices kept and renumbered consistently.
#include "solver/comesh/comesh_topology.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <optional>
#include <random>
#include <thread>
#include <utility>

#include "solver/comesh/comesh_objective.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/validate.h"
#include "tests/unit/solver/comesh/comesh_boundary_expect.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace inbetween::solver {
namespace {

double Objective(const Multimesh& m, double w = 0.5) {
  auto o = ComeshObjective::Create(m.triangles, m.shapes, w);
  EXPECT_TRUE(o.ok()) << o.status();
  return o.ok() ? o->Evaluate(m.shapes) : 0.0;
}

void ExpectValidEverywhere(const Multimesh& m) {
  EXPECT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  for (const Points& x : m.shapes) EXPECT_EQ(CountInverted(m.triangles, x), 0);
}

using testing::ExpectBoundaryKept;

Multimesh Sheared(int k, double shear) {
  Multimesh m = testing::SquareGrid(k);
  for (Point& p : m.shapes[0]) p.x() += shear * p.y();
  m.shapes.push_back(testing::Similar(m.shapes[0], 0.3, 1.5, Point(2, 0)));
  return m;
}

// EdgeUses: every edge of the live triangles once, (a, b) with a < b in increasing order, with
// its number of live triangles; checked against a map on a random triangle soup with dead
// triangles, repeated edges and unused vertex numbers.
TEST(ComeshTopologyTest, EdgeUsesCountsEveryLiveEdgeInOrder) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> vertex(0, 40);
  std::vector<Triangle> triangles;
  std::vector<char> alive;
  while (triangles.size() < 300) {
    const Triangle t{vertex(rng), vertex(rng), vertex(rng)};
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    triangles.push_back(t);
    alive.push_back(rng() % 4 != 0);
  }
  std::map<std::pair<int, int>, int> expected;
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (!alive[t]) continue;
    for (int k = 0; k < 3; ++k) {
      ++expected[std::minmax(triangles[t][k], triangles[t][(k + 1) % 3])];
    }
  }
  const auto uses = EdgeUses(triangles, alive);
  ASSERT_EQ(uses.size(), expected.size());
  size_t i = 0;
  for (const auto& [edge, count] : expected) {
    EXPECT_EQ(uses[i].first, edge);
    EXPECT_EQ(uses[i].second, count);
    ++i;
  }
  EXPECT_TRUE(EdgeUses(triangles, std::vector<char>(triangles.size(), 0)).empty());
  // The polled variant: the same list with a live token, false with a set one.
  CancelToken live, set;
  set.Cancel();
  std::vector<std::pair<std::pair<int, int>, int>> polled{{{7, 8}, 1}};
  ASSERT_TRUE(EdgeUses(triangles, alive, &live, &polled));
  EXPECT_EQ(polled, uses);
  EXPECT_FALSE(EdgeUses(triangles, alive, &set, &polled));
}

TEST(ComeshTopologyTest, FlipsLongDiagonalsOfAShearedGridInAllShapes) {
  const Multimesh m = Sheared(6, 0.8);
  TopologyOptions options;
  options.collapses = options.splits = false;
  TopologyReport report;
  auto out = ImproveTopology(m, 0.5, options, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GT(report.flips, 0);
  EXPECT_EQ(report.collapses, 0);
  EXPECT_EQ(out->num_vertices(), m.num_vertices());
  EXPECT_EQ(out->triangles.size(), m.triangles.size());
  ExpectValidEverywhere(*out);
  ExpectBoundaryKept(m, *out);
  EXPECT_LT(report.objective_after, report.objective_before);
  EXPECT_NEAR(Objective(*out), report.objective_after, 1e-9 * report.objective_after);
  EXPECT_NEAR(Objective(m), report.objective_before, 1e-9 * report.objective_before);
}

// A set token stops the pass (CANCELLED, no mesh); a live one changes nothing.
TEST(ComeshTopologyTest, CancelledPassAnswersCancelled) {
  const Multimesh m = Sheared(6, 0.8);
  CancelToken live, cancelled;
  cancelled.Cancel();
  TopologyReport plain, with_token;
  auto a = ImproveTopology(m, 0.5, TopologyOptions{}, &plain);
  auto b = ImproveTopology(m, 0.5, TopologyOptions{}, &with_token, &live);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_GT(plain.flips, 0);
  EXPECT_EQ(plain.flips, with_token.flips);
  EXPECT_EQ(a->triangles, b->triangles);
  EXPECT_EQ(a->shapes, b->shapes);
  auto c = ImproveTopology(m, 0.5, TopologyOptions{}, nullptr, &cancelled);
  EXPECT_EQ(c.status().code(), absl::StatusCode::kCancelled) << c.status();
}

// A cancel at any moment of a pass that flips and collapses (every step of it: the editor's set-up,
// the edge lists, the collapse and split candidate lists, the operations) answers CANCELLED or,
// when it came too late, exactly the uncancelled result; never a different mesh.
TEST(ComeshTopologyTest, CancelAtAnyMomentAnswersCancelledOrTheSameMesh) {
  Multimesh m = Sheared(40, 0.8);
  // Short edges (collapse candidates): every 7th vertex pulled toward its next neighbour in both
  // shapes, where that inverts no triangle.
  for (int v = 0; v + 1 < m.num_vertices(); v += 7) {
    Multimesh moved = m;
    for (Points& x : moved.shapes) x[v] = x[v + 1] + 0.15 * (x[v] - x[v + 1]);
    if (CountInverted(moved.triangles, moved.shapes[0]) == 0 &&
        CountInverted(moved.triangles, moved.shapes[1]) == 0) {
      m = std::move(moved);
    }
  }
  ASSERT_TRUE(ValidateMultimesh(m).ok());
  TopologyOptions options;
  TopologyReport report;
  const auto start = std::chrono::steady_clock::now();
  const auto expected = ImproveTopology(m, 0.5, options, &report);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(expected.ok()) << expected.status();
  ASSERT_GT(report.flips, 0);
  ASSERT_GT(report.collapses, 0);
  int cancelled = 0, finished = 0;
  constexpr int kTrials = 40;
  for (int i = 0; i < kTrials; ++i) {
    CancelToken token;
    std::thread canceller([&] {
      // Spread over the pass's time; the last trials well after it (so they finish first).
      const double delay = i < kTrials - 4 ? seconds * i / (kTrials - 4) : 4 * seconds + 0.05;
      std::this_thread::sleep_for(std::chrono::duration<double>(delay));
      token.Cancel();
    });
    const auto out = ImproveTopology(m, 0.5, options, nullptr, &token);
    canceller.join();
    if (!out.ok()) {
      EXPECT_EQ(out.status().code(), absl::StatusCode::kCancelled) << out.status();
      ++cancelled;
      continue;
    }
    ++finished;
    EXPECT_EQ(out->triangles, expected->triangles);
    EXPECT_EQ(out->shapes, expected->shapes);
  }
  EXPECT_GT(cancelled, 0);
  EXPECT_GT(finished, 0);  // the last trials start after the uncancelled pass's time
}

TEST(ComeshTopologyTest, CollapsesANeedlessVertexKeepingBoundaryAndValidity) {
  Multimesh m = testing::SquareGrid(6);
  m.shapes.push_back(testing::TutteHexagon(m));
  // Interior vertex 8 = (1, 1) pushed almost onto its neighbour 15 = (1, 2) in both shapes.
  for (Points& x : m.shapes) x[8] = x[15] + 0.08 * (x[8] - x[15]);
  ASSERT_TRUE(ValidateMultimesh(m).ok());
  m.cohesive_edges.push_back({0, 1, 1, 0});  // must be remapped, never removed
  TopologyReport report;
  auto out = ImproveTopology(m, 0.5, TopologyOptions{}, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GE(report.collapses, 1);
  EXPECT_EQ(out->num_vertices(), m.num_vertices() - report.collapses + report.splits);
  EXPECT_EQ(out->triangles.size(), m.triangles.size() - 2 * report.collapses + 2 * report.splits);
  ExpectValidEverywhere(*out);
  ExpectBoundaryKept(m, *out);
  ASSERT_EQ(out->cohesive_edges.size(), 1u);
  for (int s = 0; s < m.num_shapes(); ++s) {
    EXPECT_EQ(out->shapes[s][out->cohesive_edges[0][0]], m.shapes[s][0]);
    EXPECT_EQ(out->shapes[s][out->cohesive_edges[0][1]], m.shapes[s][1]);
  }
  EXPECT_LE(report.objective_after, report.objective_before);
  EXPECT_LE(Objective(*out), Objective(m));
}

TEST(ComeshTopologyTest, NoOperationOnAnOptimalMeshKeepsItIdentical) {
  // Two triangles, no interior edge to flip or vertex to remove.
  Multimesh m = testing::SquareGrid(1);
  m.shapes.push_back(testing::Similar(m.shapes[0], 0.2, 2.0, Point(0, 0)));
  TopologyReport report;
  auto out = ImproveTopology(m, 0.5, TopologyOptions{}, &report);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(report.flips + report.collapses + report.splits, 0);
  EXPECT_EQ(out->triangles, m.triangles);
  EXPECT_EQ(out->shapes, m.shapes);
  EXPECT_EQ(out->boundary, m.boundary);
}

TEST(ComeshTopologyTest, EveryPassOnRandomlyDistortedMeshesStaysValid) {
  for (int seed = 0; seed < 6; ++seed) {
    Multimesh m = testing::SquareGrid(8);
    m.shapes.push_back(testing::TutteHexagon(m));
    m.shapes.push_back(testing::SmoothlyDistorted(m.shapes[0], 0.03 * (seed - 3)));
    for (int pass = 0; pass < 3; ++pass) {
      TopologyReport report;
      auto out = ImproveTopology(m, 0.1 + 0.15 * seed, TopologyOptions{}, &report);
      ASSERT_TRUE(out.ok()) << out.status();
      ExpectValidEverywhere(*out);
      ExpectBoundaryKept(m, *out);
      EXPECT_LE(report.objective_after, report.objective_before);
      m = *std::move(out);
    }
  }
}

// One pass (w = 0.5) with what every pass must give: a valid multimesh in every shape, the same
// boundary point set, an objective not raised. nullopt (and a failure) if the pass failed.
std::optional<Multimesh> CheckedPass(const Multimesh& m, const TopologyOptions& options,
                                     TopologyReport* report_out = nullptr) {
  TopologyReport report;
  absl::StatusOr<Multimesh> out = ImproveTopology(m, 0.5, options, &report);
  if (report_out != nullptr) *report_out = report;
  EXPECT_TRUE(out.ok()) << out.status();
  if (!out.ok()) return std::nullopt;
  ExpectValidEverywhere(*out);
  ExpectBoundaryKept(m, *out);
  EXPECT_LE(report.objective_after, report.objective_before);
  return *std::move(out);
}

// Boundary collapses: a boundary vertex crowded against its neighbour on a straight side of
// both shapes is removed along the boundary; the square's corners (corners in both shapes) and
// a cohesive-edge vertex never are; the boundary stays the same point set, the lists stay loops.
TEST(ComeshTopologyTest, BoundaryCollapseRemovesACrowdedVertexOnAStraightSide) {
  Multimesh m = testing::SquareGrid(6);
  m.shapes.push_back(testing::Similar(m.shapes[0], 0.4, 1.7, Point(3, 1)));
  // Vertex 2 = (2/6, 0) pushed along the bottom side almost onto vertex 3, in both shapes (an
  // exact similarity keeps it on the side); vertex 5 = (5/6, 0) likewise onto the corner 6.
  for (Points& x : m.shapes) {
    x[2] = x[3] + 0.05 * (x[2] - x[3]);
    x[5] = x[6] + 0.05 * (x[5] - x[6]);
  }
  m.boundary_loops = {m.boundary};
  m.cohesive_edges.push_back({3, 4, 4, 3});  // 3 and 4 are never removed
  ASSERT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  for (bool boundary_collapses : {false, true}) {
    SCOPED_TRACE(boundary_collapses);
    TopologyOptions options;
    options.boundary_collapses = boundary_collapses;
    const std::optional<Multimesh> out = CheckedPass(m, options);
    ASSERT_TRUE(out.has_value());
    ASSERT_EQ(out->boundary_loops.size(), 1u);
    EXPECT_EQ(out->boundary_loops[0], out->boundary);
    auto on_boundary = [&](const Point& p) {
      int found = 0;
      for (int v : out->boundary) found += out->shapes[0][v] == p;
      return found;
    };
    if (!boundary_collapses) {
      EXPECT_EQ(out->boundary.size(), m.boundary.size());
      continue;
    }
    // 2 (crowding 3) and 5 (crowding the corner) are gone; everything else on the boundary stays.
    EXPECT_EQ(on_boundary(m.shapes[0][2]), 0);
    EXPECT_EQ(on_boundary(m.shapes[0][5]), 0);
    EXPECT_EQ(out->boundary.size(), m.boundary.size() - 2);
    for (int v : {0, 3, 4, 6}) EXPECT_EQ(on_boundary(m.shapes[0][v]), 1) << v;
    ASSERT_EQ(out->cohesive_edges.size(), 1u);
    EXPECT_EQ(out->shapes[1][out->cohesive_edges[0][0]], m.shapes[1][3]);
    EXPECT_EQ(out->shapes[1][out->cohesive_edges[0][1]], m.shapes[1][4]);
  }
}

// A boundary vertex on a straight side of one shape but at a corner of the other is never removed:
// the square grid's boundary on a hexagon (Tutte), crowded in many places; only vertices straight
// in both shapes may go.
// A right-angle corner v whose neighbour a has slid along the side to within 1e-10 of it: v is
// off the line a-b by less than 1e-9 |ab| (the old tolerance took it for straight, so a corner of
// pentagon_star/hard4 became a slider and moved ~1e-9), but the polyline turns by 90 degrees.
TEST(ComeshTopologyTest, StrictlyInsideSegmentJudgesTheTurnNotTheDistance) {
  const Point v(0.0, 0.0), b(0.0, 1.0);
  EXPECT_FALSE(StrictlyInsideSegment(Point(1e-10, 0.0), b, v));
  EXPECT_FALSE(StrictlyInsideSegment(Point(1e-13, 0.0), b, v));
  // Straight, however close to either end, and with roundoff off the line.
  EXPECT_TRUE(StrictlyInsideSegment(Point(0.0, -1e-10), b, v));
  EXPECT_TRUE(StrictlyInsideSegment(Point(0.0, -1.0), b, Point(1e-17, 0.999999)));
  // A turn of 1e-8 radians is a corner, 1e-10 is not; ends and points beyond them are not inside.
  EXPECT_FALSE(StrictlyInsideSegment(Point(0.0, -1.0), b, Point(1e-8, 0.0)));
  EXPECT_TRUE(StrictlyInsideSegment(Point(0.0, -1.0), b, Point(1e-10, 0.0)));
  EXPECT_FALSE(StrictlyInsideSegment(Point(0.0, -1.0), b, b));
  EXPECT_FALSE(StrictlyInsideSegment(Point(0.0, -1.0), b, Point(0.0, 2.0)));
}

TEST(ComeshTopologyTest, BoundaryCollapseKeepsCornersOfEveryShape) {
  Multimesh m = testing::SquareGrid(12);
  m.shapes.push_back(testing::TutteHexagon(m));
  m.boundary_loops = {m.boundary};
  // Every third boundary vertex that is on a straight side in both shapes is crowded onto its
  // successor (a corner of one shape, sometimes) along that side.
  const int nb = static_cast<int>(m.boundary.size());
  for (int i = 0; i < nb; i += 3) {
    const int p = m.boundary[(i + nb - 1) % nb], v = m.boundary[i], q = m.boundary[(i + 1) % nb];
    bool straight = true;
    for (const Points& x : m.shapes) straight &= StrictlyInsideSegment(x[p], x[q], x[v]);
    if (!straight) continue;
    for (Points& x : m.shapes) x[v] = x[q] + 0.1 * (x[v] - x[q]);
  }
  ASSERT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  const size_t boundary_before = m.boundary.size();
  for (int pass = 0; pass < 4; ++pass) {
    TopologyOptions options;
    options.collapse_ratio = 3.0;  // every boundary edge is a candidate
    std::optional<Multimesh> out = CheckedPass(m, options);
    ASSERT_TRUE(out.has_value());
    m = *std::move(out);
  }
  EXPECT_LT(m.boundary.size(), boundary_before);  // some straight-in-both vertices did go
}

// Corner swaps: shape 1 is the same square with its boundary turned back by one vertex, so the
// corner of shape 1 is the boundary neighbour before each corner of shape 0, and each of the two
// crowds the other's corner (in shape 0 the shape-1 corner vertex is pushed along the side to a
// tenth of its distance from the square's corner, likewise in shape 1). A swap merges the two
// into a corner of both shapes, dropping the crowded triangles; the boundary stays the same
// point set in both shapes and the map energy falls. Not with corner_swaps off, and never at a
// cohesive-edge vertex.
TEST(ComeshTopologyTest, CornerSwapsMergeNeighbouringCornersOfTwoShapes) {
  const int k = 8;
  Multimesh m = testing::SquareGrid(k);
  const int nb = static_cast<int>(m.boundary.size());
  Points turned = m.shapes[0];
  for (int b = 0; b < nb; ++b) turned[m.boundary[b]] = m.shapes[0][m.boundary[(b + 1) % nb]];
  m.shapes.push_back(testing::TutteInterior(m, std::move(turned)));
  for (int i = 0; i < nb; i += k) {
    const int corner0 = m.boundary[i], corner1 = m.boundary[(i + nb - 1) % nb];
    Points& x0 = m.shapes[0];
    Points& x1 = m.shapes[1];
    x0[corner1] = x0[corner0] + 0.1 * (x0[corner1] - x0[corner0]);
    x1[corner0] = x1[corner1] + 0.1 * (x1[corner0] - x1[corner1]);
  }
  m.boundary_loops = {m.boundary};
  // The pair at the corner (1, 0) of shape 0 (boundary[k]) is a cohesive edge.
  m.cohesive_edges.push_back({m.boundary[k - 1], m.boundary[k], m.boundary[k], m.boundary[k - 1]});
  ASSERT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  auto corners_of_both = [](const Multimesh& mesh) {
    int count = 0;
    const std::vector<int>& loop = mesh.boundary;
    const size_t n = loop.size();
    for (size_t i = 0; i < n; ++i) {
      bool corner = true;
      for (const Points& x : mesh.shapes) {
        corner &= !StrictlyInsideSegment(x[loop[(i + n - 1) % n]], x[loop[(i + 1) % n]], x[loop[i]]);
      }
      count += corner;
    }
    return count;
  };
  auto map_energy = [](const Multimesh& mesh) {
    auto o = ComeshObjective::Create(mesh.triangles, mesh.shapes, 0.5);
    EXPECT_TRUE(o.ok()) << o.status();
    ComeshEnergies e;
    if (o.ok()) o->Evaluate(mesh.shapes, nullptr, &e);
    return e.map;
  };
  ASSERT_EQ(corners_of_both(m), 0);
  for (bool swaps : {false, true}) {
    SCOPED_TRACE(swaps);
    TopologyOptions options;
    options.corner_swaps = swaps;
    TopologyReport report;
    const std::optional<Multimesh> out = CheckedPass(m, options, &report);
    ASSERT_TRUE(out.has_value());
    if (!swaps) {
      EXPECT_EQ(report.corner_swaps, 0);
      EXPECT_EQ(corners_of_both(*out), 0);
      continue;
    }
    // Three of the four corner pairs merge; the cohesive one stays apart.
    EXPECT_EQ(report.corner_swaps, 3);
    EXPECT_EQ(corners_of_both(*out), 3);
    EXPECT_EQ(out->boundary.size(), m.boundary.size() - 3);
    EXPECT_LT(map_energy(*out), map_energy(m));
    ASSERT_EQ(out->cohesive_edges.size(), 1u);
    for (int s = 0; s < 2; ++s) {
      EXPECT_EQ(out->shapes[s][out->cohesive_edges[0][0]], m.shapes[s][m.boundary[k - 1]]);
      EXPECT_EQ(out->shapes[s][out->cohesive_edges[0][1]], m.shapes[s][m.boundary[k]]);
    }
  }
}

// Boundary splits: on the bottom side of an 8 x 8 grid (both shapes, the second a similarity of
// the first), vertices 1 and 2 are pushed along the side towards 0 and 3, leaving the boundary
// edge (1, 2) 2.8 times the grid spacing long. A pass (collapses off) splits it: a new boundary
// vertex inside it on the side, the loops and `boundary` list it between 1 and 2, the mesh stays
// valid and the boundary the same point set. With boundary_splits off nothing lands there.
TEST(ComeshTopologyTest, BoundarySplitsCutALongBoundaryEdge) {
  Multimesh m = testing::SquareGrid(8);
  Points& x = m.shapes[0];
  x[1] = x[0] + 0.1 * (x[1] - x[0]);
  x[2] = x[3] + 0.1 * (x[2] - x[3]);
  m.shapes.push_back(testing::Similar(m.shapes[0], 0.4, 1.7, Point(3, 1)));
  m.boundary_loops = {m.boundary};
  ASSERT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  const double x1 = m.shapes[0][1].x(), x2 = m.shapes[0][2].x();
  for (bool splits : {false, true}) {
    SCOPED_TRACE(splits);
    TopologyOptions options;
    options.collapses = false;
    options.boundary_splits = splits;
    TopologyReport report;
    const std::optional<Multimesh> out = CheckedPass(m, options, &report);
    ASSERT_TRUE(out.has_value());
    ASSERT_EQ(out->boundary_loops.size(), 1u);
    EXPECT_EQ(out->boundary_loops[0], out->boundary);
    std::vector<int> inside;  // boundary vertices strictly between the old 1 and 2
    for (int v : out->boundary) {
      const Point& p = out->shapes[0][v];
      if (p.y() == 0.0 && p.x() > x1 + 1e-9 && p.x() < x2 - 1e-9) inside.push_back(v);
    }
    if (!splits) {
      EXPECT_TRUE(inside.empty());
      EXPECT_EQ(out->boundary.size(), m.boundary.size());
      continue;
    }
    ASSERT_EQ(inside.size(), 1u);
    EXPECT_GE(report.splits, 1);
    EXPECT_EQ(out->boundary.size(), m.boundary.size() + 1);
    EXPECT_NEAR(out->shapes[0][inside[0]].x(), 0.5 * (x1 + x2), 1e-12);
    // Listed between 1 and 2 (numbering kept for the old vertices, new ones appended).
    const std::vector<int>& loop = out->boundary;
    const auto at = std::find(loop.begin(), loop.end(), inside[0]) - loop.begin();
    ASSERT_GT(at, 0);
    EXPECT_EQ(loop[at - 1], 1);
    EXPECT_EQ(loop[(at + 1) % loop.size()], 2);
  }
}

// Twice the area of shape s's boundary polygon (the loop as listed).
double LoopArea2(const Multimesh& m, int s) {
  const Points& x = m.shapes.at(s);
  double a = 0.0;
  for (size_t k = 0; k < m.boundary.size(); ++k) {
    const Point& p = x[m.boundary[k]];
    const Point& q = x[m.boundary[(k + 1) % m.boundary.size()]];
    a += Cross(p, q);
  }
  return a;
}

// The unit square, corners 0-3, with interior vertex 4 pressed almost onto the bottom edge (0, 1)
// and interior vertex 5 above it; shape 1 a similar copy. Triangle (0, 1, 4) is a cap sliver
// (quality ~0.012 at height 0.005) in both shapes.
Multimesh CapOnTheBoundary(double height) {
  Multimesh m;
  m.shapes.push_back(
      {Point(0, 0), Point(1, 0), Point(1, 1), Point(0, 1), Point(0.5, height), Point(0.5, 0.6)});
  m.shapes.push_back(testing::Similar(m.shapes[0], 0.3, 1.5, Point(2, 0)));
  m.triangles = {{0, 1, 4}, {1, 5, 4}, {0, 4, 5}, {1, 2, 5}, {0, 5, 3}, {3, 5, 2}};
  m.boundary = {0, 1, 2, 3};
  m.boundary_loops = {m.boundary};
  return m;
}

TEST(ComeshSliverTest, TriangleQualityIsOneForEquilateralAndZeroForFlat) {
  EXPECT_NEAR(TriangleQuality(Point(0, 0), Point(1, 0), Point(0.5, std::sqrt(0.75))), 1.0, 1e-12);
  EXPECT_EQ(TriangleQuality(Point(0, 0), Point(1, 0), Point(2, 0)), 0.0);
  EXPECT_LT(TriangleQuality(Point(0, 0), Point(0.5, 1), Point(1, 0)), 0.0);  // clockwise
  EXPECT_EQ(TriangleQuality(Point(1, 1), Point(1, 1), Point(1, 1)), 0.0);
}

// A cap on the boundary: vertex 4 moves onto edge (0, 1) and joins the boundary between 0 and 1;
// the sliver goes, every shape's domain stays the same, the numbering is kept.
TEST(ComeshSliverTest, SnapsAnInteriorVertexOntoTheBoundaryEdgeUnderIt) {
  const Multimesh m = CapOnTheBoundary(0.005);
  ASSERT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  ASSERT_LT(WorstQuality(m), 0.02);
  SliverReport report;
  absl::StatusOr<Multimesh> out = RemoveSlivers(m, 0.5, 0.02, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  ExpectValidEverywhere(*out);
  EXPECT_EQ(report.slivers_before, 1);
  EXPECT_EQ(report.slivers_after, 0);
  EXPECT_EQ(report.operations, 1);
  EXPECT_EQ(report.snaps, 1);
  EXPECT_EQ(out->num_vertices(), m.num_vertices());
  EXPECT_EQ(out->triangles.size(), m.triangles.size() - 1);
  EXPECT_EQ(out->boundary, (std::vector<int>{0, 4, 1, 2, 3}));
  EXPECT_EQ(out->boundary_loops, std::vector<std::vector<int>>{out->boundary});
  EXPECT_GT(report.worst_quality_after, 0.3);
  EXPECT_EQ(report.worst_quality_after, WorstQuality(*out));
  for (int s = 0; s < 2; ++s) {
    EXPECT_NEAR(LoopArea2(*out, s), LoopArea2(m, s), 1e-12) << "shape " << s;
    const Point& a = out->shapes[s][0];
    const Point& b = out->shapes[s][1];
    const Point& c = out->shapes[s][4];
    EXPECT_NEAR(Cross(c - a, b - a), 0.0, 1e-12);
  }
}

// Below the threshold only: the same cap at a height that leaves quality above min_quality, and a
// mesh without slivers, come back unchanged.
TEST(ComeshSliverTest, LeavesTrianglesAboveTheThresholdAlone) {
  for (const Multimesh& m : {CapOnTheBoundary(0.1), testing::SquareGrid(4)}) {
    ASSERT_GT(WorstQuality(m), 0.02);
    SliverReport report;
    absl::StatusOr<Multimesh> out = RemoveSlivers(m, 0.5, 0.02, &report);
    ASSERT_TRUE(out.ok()) << out.status();
    EXPECT_EQ(report.slivers_before, 0);
    EXPECT_EQ(report.operations, 0);
    EXPECT_EQ(out->triangles, m.triangles);
    EXPECT_EQ(out->shapes, m.shapes);
    EXPECT_EQ(out->boundary, m.boundary);
  }
}

// Two boundary neighbours that coincide where one of them is a corner (a slider that slid onto
// its neighbour): the bottom side of a grid gets vertex 1 almost onto corner 0, exactly on the
// side in shape 0 but 1e-8 off it in shape 1 (a corner there, so no plain boundary collapse may
// take it). Sliver removal merges the two, keeping corner 0 where it is and every shape's
// boundary polygon within that tiny corner.
TEST(ComeshSliverTest, MergesBoundaryNeighboursThatCoincide) {
  Multimesh m = testing::SquareGrid(6);
  m.shapes.push_back(testing::Similar(m.shapes[0], 0.4, 1.7, Point(3, 1)));
  m.boundary_loops = {m.boundary};
  for (int s = 0; s < 2; ++s) {
    Points& x = m.shapes[s];
    x[1] = x[0] + 1e-6 * (x[1] - x[0]);
  }
  const Point side = m.shapes[1][6] - m.shapes[1][0];
  m.shapes[1][1] += 1e-8 * Point(-side.y(), side.x()) / side.norm();  // inwards
  ASSERT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  ASSERT_LT(WorstQuality(m), 1e-3);
  SliverReport report;
  absl::StatusOr<Multimesh> out = RemoveSlivers(m, 0.5, 0.02, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  ExpectValidEverywhere(*out);
  EXPECT_EQ(report.slivers_after, 0);
  EXPECT_GT(WorstQuality(*out), 0.02);
  EXPECT_EQ(out->num_vertices(), m.num_vertices() - 1);
  EXPECT_EQ(out->boundary.size(), m.boundary.size() - 1);
  for (int s = 0; s < 2; ++s) {
    int at_corner = 0;
    for (int v : out->boundary) at_corner += out->shapes[s][v] == m.shapes[s][0];
    EXPECT_EQ(at_corner, 1) << "shape " << s;
    EXPECT_NEAR(LoopArea2(*out, s), LoopArea2(m, s), 1e-8) << "shape " << s;
  }
}

}  // namespace
}  // namespace inbetween::solver
