// Tests for the comesh objective: (1 - w) ODT + w cyclic MIPS, gradient and reported energies.
#include "solver/comesh/comesh_objective.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace inbetween::solver {
namespace {

double RelativeGradientError(const ComeshObjective& o, const std::vector<Points>& shapes) {
  std::vector<Points> g;
  o.Evaluate(shapes, &g);
  double err2 = 0.0, norm2 = 0.0;
  const double h = 1e-7;
  for (size_t s = 0; s < shapes.size(); ++s) {
    for (size_t v = 0; v < shapes[s].size(); ++v) {
      for (int c = 0; c < 2; ++c) {
        std::vector<Points> p = shapes, m = shapes;
        p[s][v][c] += h;
        m[s][v][c] -= h;
        const double fd = (o.Evaluate(p) - o.Evaluate(m)) / (2 * h);
        err2 += (fd - g[s][v][c]) * (fd - g[s][v][c]);
        norm2 += g[s][v][c] * g[s][v][c];
      }
    }
  }
  return std::sqrt(err2 / norm2);
}

TEST(ComeshObjectiveTest, GradientMatchesFiniteDifferences) {
  const Multimesh m = testing::SquareGrid(4);
  const Points a = testing::SmoothlyDistorted(m.shapes[0], 0.07);
  const Points b = testing::TutteHexagon(m);
  const Points c =
      testing::Similar(testing::SmoothlyDistorted(m.shapes[0], -0.05), 0.4, 2.0, Point(1, 1));
  for (double w : {0.0, 0.3, 0.5, 1.0}) {
    for (const std::vector<Points>& shapes :
         {std::vector<Points>{a}, std::vector<Points>{a, b}, std::vector<Points>{a, b, c}}) {
      auto o = ComeshObjective::Create(m.triangles, shapes, w);
      ASSERT_TRUE(o.ok()) << o.status();
      EXPECT_LT(RelativeGradientError(*o, shapes), 1e-5)
          << "w = " << w << ", shapes = " << shapes.size();
    }
  }
}

// Area-invariant mode (outline sliding): the normalizers follow the current areas, so the
// gradient has a term on the boundary vertices; checked away from the rest shapes (areas changed
// by a boundary distortion and a scaling).
TEST(ComeshObjectiveTest, AreaInvariantGradientMatchesFiniteDifferences) {
  const Multimesh m = testing::SquareGrid(4);
  const Points a = testing::SmoothlyDistorted(m.shapes[0], 0.07);
  const Points b = testing::TutteHexagon(m);
  auto bulged = [](Points x, double amount) {  // moves the boundary too: the area changes
    for (Point& p : x) p += amount * Point(std::sin(3.0 * p.y()), std::cos(2.0 * p.x()));
    return x;
  };
  const std::vector<Points> rest = {a, b};
  const std::vector<Points> at = {bulged(a, 0.02), testing::Similar(bulged(b, -0.015), 1.3, 0.2,
                                                                    Point(0.1, 0))};
  for (double w : {0.0, 0.5, 1.0}) {
    auto o = ComeshObjective::Create(m.triangles, rest, w, 1, /*area_invariant=*/true);
    ASSERT_TRUE(o.ok()) << o.status();
    EXPECT_LT(RelativeGradientError(*o, at), 1e-5) << "w = " << w;
  }
}

// Area-invariant mode: scaling a shape changes nothing (the plain objective would drop with the
// area), and at the rest shapes it equals the plain objective.
TEST(ComeshObjectiveTest, AreaInvariantIgnoresScaleAndEqualsPlainAtRest) {
  const Multimesh m = testing::SquareGrid(6);
  const std::vector<Points> rest = {m.shapes[0], testing::TutteHexagon(m)};
  auto plain = ComeshObjective::Create(m.triangles, rest, 0.5);
  auto invariant = ComeshObjective::Create(m.triangles, rest, 0.5, 1, /*area_invariant=*/true);
  ASSERT_TRUE(plain.ok() && invariant.ok());
  ComeshEnergies e_plain, e_invariant;
  EXPECT_NEAR(invariant->Evaluate(rest, nullptr, &e_invariant),
              plain->Evaluate(rest, nullptr, &e_plain), 1e-12);
  const std::vector<Points> shrunk = {testing::Similar(rest[0], 0.0, 0.9, Point(0, 0)),
                                      testing::Similar(rest[1], 0.3, 0.8, Point(2, 0))};
  ComeshEnergies e_shrunk;
  EXPECT_NEAR(invariant->Evaluate(shrunk, nullptr, &e_shrunk), e_invariant.objective, 1e-12);
  EXPECT_NEAR(e_shrunk.map, e_invariant.map, 1e-12);
  EXPECT_NEAR(e_shrunk.mesh, e_invariant.mesh, 1e-12);
  EXPECT_LT(plain->Evaluate(shrunk), e_plain.objective - 0.1);  // what outline sliding exploited
}

TEST(ComeshObjectiveTest, ReportsConformalAndGridEnergies) {
  const Multimesh m = testing::SquareGrid(6);
  const std::vector<Points> shapes = {m.shapes[0],
                                      testing::Similar(m.shapes[0], 0.9, 3.0, Point(5, 1))};
  auto o = ComeshObjective::Create(m.triangles, shapes, 0.25);
  ASSERT_TRUE(o.ok());
  ComeshEnergies e;
  const double f = o->Evaluate(shapes, nullptr, &e);
  EXPECT_NEAR(e.map, 2.0, 1e-12);
  EXPECT_NEAR(e.mesh, 2.0 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(f, 2 * (0.75 * e.mesh + 0.25 * e.map), 1e-12);
  EXPECT_EQ(e.objective, f);
}

// A live token changes nothing; a set one gives NaN; a cancel at any moment of a parallel
// evaluation gives NaN or exactly the uncancelled value (never a partial sum).
TEST(ComeshObjectiveTest, CancelGivesNaNOrTheExactValue) {
  const Multimesh m = testing::SquareGrid(100);  // 20,000 triangles: parallel chunks
  const std::vector<Points> shapes = {testing::SmoothlyDistorted(m.shapes[0], 0.05),
                                      testing::TutteHexagon(m)};
  auto o = ComeshObjective::Create(m.triangles, shapes, 0.5, /*threads=*/2);
  ASSERT_TRUE(o.ok()) << o.status();
  std::vector<Points> g, g_live;
  const double f = o->Evaluate(shapes, &g);
  CancelToken live, set;
  set.Cancel();
  EXPECT_EQ(o->Evaluate(shapes, &g_live, nullptr, &live), f);
  EXPECT_EQ(g_live, g);
  EXPECT_TRUE(std::isnan(o->Evaluate(shapes, &g_live, nullptr, &set)));
  // Cancels spread from the start to 1.5 times the length of an evaluation measured here (a
  // fixed schedule missed every evaluation under a loaded ctest -j2: all 60 finished first);
  // more rounds while none landed in time, since the canceller may be scheduled late.
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(o->Evaluate(shapes, nullptr, nullptr, &live), f);
  const std::chrono::duration<double> whole = std::chrono::steady_clock::now() - start;
  int nan = 0;
  for (int round = 0; round < 5 && nan == 0; ++round) {
    for (int i = 0; i < 60; ++i) {
      CancelToken token;
      std::atomic<bool> started{false};
      std::thread canceller([&] {
        while (!started.load()) std::this_thread::yield();
        std::this_thread::sleep_for(whole * i / 40);
        token.Cancel();
      });
      started = true;
      const double value = o->Evaluate(shapes, nullptr, nullptr, &token);
      canceller.join();
      if (std::isnan(value)) {
        ++nan;
      } else {
        EXPECT_EQ(value, f) << "round " << round << ", trial " << i;
      }
    }
  }
  EXPECT_GT(nan, 0);
}

TEST(ComeshObjectiveTest, InvertedShapeGivesInfinity) {
  const Multimesh m = testing::SquareGrid(3);
  std::vector<Points> shapes = {m.shapes[0], m.shapes[0]};
  auto o = ComeshObjective::Create(m.triangles, shapes);
  ASSERT_TRUE(o.ok());
  shapes[1][5] = Point(2.0, 2.0);  // interior vertex thrown outside: flips triangles
  EXPECT_TRUE(std::isinf(o->Evaluate(shapes)));
}

TEST(ComeshObjectiveTest, RejectsBadInput) {
  const Multimesh m = testing::SquareGrid(2);
  EXPECT_FALSE(ComeshObjective::Create(m.triangles, {}).ok());
  EXPECT_FALSE(ComeshObjective::Create(m.triangles, {m.shapes[0]}, 1.5).ok());
  Points shorter = m.shapes[0];
  shorter.pop_back();
  EXPECT_FALSE(ComeshObjective::Create(m.triangles, {m.shapes[0], shorter}).ok());
  std::vector<Triangle> bad = m.triangles;
  bad[0][1] = 99;
  EXPECT_FALSE(ComeshObjective::Create(bad, {m.shapes[0]}).ok());
}

}  // namespace
}  // namespace inbetween::solver
