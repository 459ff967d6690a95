// Tests for the comesh outer loop's topology pass: flips and collapses valid in every shape,
// objective never increases, boundary and cohesive vertices kept and renumbered consistently.
#include "solver/comesh/comesh_topology.h"

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <random>
#include <thread>
#include <utility>

#include "solver/comesh/comesh_objective.h"
#include "solver/mesh/validate.h"
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

// Boundary positions, in boundary order, must survive any pass unchanged in every shape.
void ExpectSameBoundary(const Multimesh& before, const Multimesh& after) {
  ASSERT_EQ(before.boundary.size(), after.boundary.size());
  for (int s = 0; s < before.num_shapes(); ++s) {
    for (size_t b = 0; b < before.boundary.size(); ++b) {
      EXPECT_EQ(before.shapes[s][before.boundary[b]], after.shapes[s][after.boundary[b]]);
    }
  }
}

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
  ExpectSameBoundary(m, *out);
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
  ExpectSameBoundary(m, *out);
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
      ExpectSameBoundary(m, *out);
      EXPECT_LE(report.objective_after, report.objective_before);
      m = *std::move(out);
    }
  }
}

}  // namespace
}  // namespace inbetween::solver
