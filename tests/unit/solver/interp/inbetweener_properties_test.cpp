// Properties of the kZhu17 inbetweener: a 4x1 bar curled 270 degrees, non-overlap,
// dynamics (epsilon = 0 is the plain inbetween), stiffness regions, warm starts.
#include <gtest/gtest.h>

#include <numbers>

#include "solver/interp/inbetweener.h"
#include "solver/interp/overlap.h"
#include "solver/interp/timing.h"
#include "tests/unit/solver/interp/test_meshes.h"

namespace inbetween::solver {
namespace {

using interp_test::BentAboutCentre;
using interp_test::GridMesh;
using interp_test::MaxDistance;
using interp_test::TotalArea;

constexpr double kPi = std::numbers::pi;

Multimesh CurledBar(double angle) {
  Multimesh mesh = GridMesh(80, 20, 0.05);  // 81 x 21 vertices, 4 x 1
  mesh.shapes.push_back(BentAboutCentre(mesh.shapes[0], 4.0, angle));
  return mesh;
}

struct SequenceStats {
  int max_inverted = 0;
  int total_inverted = 0;
  int max_overlaps = 0;
  double max_area_error = 0.0;
  int key_misses = 0;
};

SequenceStats RunSequence(const Multimesh& mesh, InbetweenOptions o, int frames) {
  absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, o);
  EXPECT_TRUE(ib.ok()) << ib.status();
  absl::StatusOr<Schedule> schedule = MakeSchedule(mesh.num_shapes(), frames);
  EXPECT_TRUE(schedule.ok());
  const double area = TotalArea(mesh.shapes[0], mesh.triangles);
  SequenceStats stats;
  FrameSequence sequence(&*ib);
  for (int k = 0; k < frames; ++k) {
    FrameReport report;
    absl::StatusOr<Frame> f = sequence.Next(schedule->frames[k].weights, nullptr, &report);
    EXPECT_TRUE(f.ok()) << f.status();
    stats.max_inverted = std::max(stats.max_inverted, report.inverted);
    stats.total_inverted += report.inverted;
    stats.max_overlaps = std::max(stats.max_overlaps, report.overlaps);
    stats.max_area_error = std::max(stats.max_area_error,
                                    std::abs(TotalArea(f->vertices, mesh.triangles) - area) / area);
    for (int i = 0; i < mesh.num_shapes(); ++i) {
      if (schedule->keys[i] == k &&
          MaxDistance(f->vertices, mesh.shapes[i]) > 1e-6 * std::sqrt(area)) {
        ++stats.key_misses;
      }
    }
  }
  return stats;
}

TEST(InterpPropertiesTest, BarCurled270KeepsAreaAndNeverInverts) {
  const Multimesh mesh = CurledBar(1.5 * kPi);
  InbetweenOptions o;
  const SequenceStats zhu = RunSequence(mesh, o, 25);
  EXPECT_EQ(zhu.max_inverted, 0);
  EXPECT_EQ(zhu.max_overlaps, 0);
  EXPECT_LT(zhu.max_area_error, 0.05);
  EXPECT_EQ(zhu.key_misses, 0);
  o.method = InterpMethod::kLinear;
  const SequenceStats linear = RunSequence(mesh, o, 25);
  EXPECT_GT(linear.max_area_error, 0.05);  // linear collapses the curl
  o.method = InterpMethod::kAlexa;
  const SequenceStats alexa = RunSequence(mesh, o, 25);
  std::printf("270-degree curl: inverted triangles over 25 frames: zhu17 %d, alexa %d, linear %d\n",
              zhu.total_inverted, alexa.total_inverted, linear.total_inverted);
}

TEST(InterpPropertiesTest, KeysExactAndNoFoldsWithWarmStartsAndManyExamples) {
  Multimesh mesh = GridMesh(16, 4, 0.25);
  for (double a : {0.5 * kPi, -0.5 * kPi, kPi, 0.0}) {
    mesh.shapes.push_back(BentAboutCentre(mesh.shapes[0], 4.0, a == 0.0 ? 0.3 : a));
  }
  for (bool warm : {false, true}) {
    InbetweenOptions o;
    o.warm_start = warm;
    const SequenceStats s = RunSequence(mesh, o, 41);
    EXPECT_EQ(s.max_inverted, 0) << warm;
    EXPECT_EQ(s.max_overlaps, 0) << warm;
    EXPECT_EQ(s.key_misses, 0) << warm;
  }
}

TEST(InterpPropertiesTest, WarmStartMatchesColdStartToTolerance) {
  const Multimesh mesh = CurledBar(kPi);
  absl::StatusOr<Schedule> schedule = MakeSchedule(2, 13);
  ASSERT_TRUE(schedule.ok());
  InbetweenOptions cold, warm;
  cold.warm_start = false;
  cold.max_iterations = warm.max_iterations = 300;
  cold.displacement_tolerance = warm.displacement_tolerance = 1e-7;
  absl::StatusOr<Inbetweener> a = Inbetweener::Create(mesh, cold);
  absl::StatusOr<Inbetweener> b = Inbetweener::Create(mesh, warm);
  ASSERT_TRUE(a.ok() && b.ok());
  Frame previous;
  for (const FrameTiming& timing : schedule->frames) {
    absl::StatusOr<Frame> fa = a->Solve(timing.weights, previous);
    absl::StatusOr<Frame> fb = b->Solve(timing.weights, previous);
    ASSERT_TRUE(fa.ok() && fb.ok());
    EXPECT_LT(MaxDistance(fa->vertices, fb->vertices), 1e-3) << timing.time;
    previous = *fb;
  }
}

TEST(InterpPropertiesTest, EpsilonZeroEqualsPlainAndDynamicsKeepsKeys) {
  const Multimesh mesh = CurledBar(kPi);
  absl::StatusOr<Schedule> schedule = MakeSchedule(2, 13);
  ASSERT_TRUE(schedule.ok());
  InbetweenOptions plain_options, zero, dynamic;
  zero.epsilon = 0.0;
  dynamic.epsilon = 400.0;
  absl::StatusOr<Inbetweener> plain = Inbetweener::Create(mesh, plain_options);
  absl::StatusOr<Inbetweener> with_zero = Inbetweener::Create(mesh, zero);
  absl::StatusOr<Inbetweener> with_dynamics = Inbetweener::Create(mesh, dynamic);
  ASSERT_TRUE(plain.ok() && with_zero.ok() && with_dynamics.ok());
  FrameSequence zero_sequence(&*with_zero), dynamic_sequence(&*with_dynamics);
  Frame previous;
  double max_difference = 0.0;
  for (size_t k = 0; k < schedule->frames.size(); ++k) {
    const ExampleWeights& w = schedule->frames[k].weights;
    absl::StatusOr<Frame> p = plain->Solve(w, previous);
    absl::StatusOr<Frame> z = zero_sequence.Next(w);
    FrameReport report;
    absl::StatusOr<Frame> d = dynamic_sequence.Next(w, nullptr, &report);
    ASSERT_TRUE(p.ok() && z.ok() && d.ok());
    EXPECT_EQ(p->vertices, z->vertices) << k;  // bit-identical
    EXPECT_EQ(report.inverted, 0);
    if (k == 0 || k + 1 == schedule->frames.size()) {
      EXPECT_EQ(d->vertices, p->vertices);  // keys stay exact
    } else if (k >= 2) {
      EXPECT_GT(report.xi, 0.0);
    }
    max_difference = std::max(max_difference, MaxDistance(p->vertices, d->vertices));
    previous = *p;
  }
  EXPECT_GT(max_difference, 1e-4);  // dynamics does something
}

TEST(InterpOverlapTest, DetectsABoundaryVertexInsideAndCrossings) {
  // Two unit squares (separate components); move the second onto the first.
  Multimesh mesh = GridMesh(1, 1);
  const Multimesh other = GridMesh(1, 1);
  for (const Point& p : other.shapes[0]) mesh.shapes[0].push_back(p + Point(3, 0));
  for (Triangle t : other.triangles) mesh.triangles.push_back({t[0] + 4, t[1] + 4, t[2] + 4});
  OverlapChecker checker(mesh.triangles, {}, 8);
  Coords x = ToCoords(mesh.shapes[0]);
  EXPECT_EQ(checker.Count(x), 0);
  for (int v = 4; v < 8; ++v) x.row(v) -= Eigen::RowVector2d(2.5, -0.3);  // corner inside
  EXPECT_GT(checker.Count(x), 0);
  EXPECT_FALSE(checker.Contacts(x).empty());
}

TEST(InterpOverlapTest, CurlBeyondAFullTurnIsPushedApart) {
  // Keys: straight bar and the bar curled 400 degrees about its centre line (a self-overlapping
  // spiral would result from a naive inbetween); zhu17's frames are checked for overlaps.
  Multimesh mesh = GridMesh(40, 5, 0.1);  // 4 x 0.5
  Points curled;
  const double angle = 2.0 * kPi * 400.0 / 360.0, r = 4.0 / angle;
  for (const Point& p : mesh.shapes[0]) {
    const double a = p.x() / r, rr = r - (p.y() - 0.25) + 0.15 * a;  // a widening spiral
    curled.emplace_back(rr * std::sin(a), r - rr * std::cos(a));
  }
  mesh.shapes.push_back(curled);
  absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, InbetweenOptions{});
  ASSERT_TRUE(ib.ok()) << ib.status();
  FrameReport report;
  absl::StatusOr<Frame> f = ib->Solve({0.2, 0.8}, Frame{}, nullptr, &report);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(report.overlaps, 0);
  EXPECT_EQ(report.inverted, 0);
}

// Two unit squares side by side; the right one's lower-left corner pushed 0.3 into the left one.
// The plain closest boundary point (among segments not incident to the vertex) is on the right
// square's own bottom edge (0.3 away along the boundary from its corner) or the left square's
// right edge; the contact must lead out of the left square, the material the corner entered.
TEST(InterpOverlapTest, ContactLeadsOutOfTheMaterialEntered) {
  Multimesh mesh = GridMesh(1, 1);
  const Multimesh other = GridMesh(1, 1);
  for (const Point& p : other.shapes[0]) mesh.shapes[0].push_back(p + Point(1.1, 0.0));
  for (Triangle t : other.triangles) mesh.triangles.push_back({t[0] + 4, t[1] + 4, t[2] + 4});
  OverlapChecker checker(mesh.triangles, {}, 8);
  Coords x = ToCoords(mesh.shapes[0]);
  x.row(4) = Eigen::RowVector2d(0.75, 0.5);  // right square's corner (1.1, 0) into the left one
  const std::vector<OverlapContact> contacts = checker.Contacts(x);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].vertex, 4);
  // The left square's nearest side is x = 1 (0.25 away): the target is just past it, outward.
  EXPECT_NEAR(contacts[0].target.y(), 0.5, 1e-12);
  EXPECT_GT(contacts[0].target.x(), 1.0);
  EXPECT_LT(contacts[0].target.x(), 1.02);
  EXPECT_NEAR(contacts[0].normal.x(), 1.0, 1e-12);
  EXPECT_NEAR(contacts[0].normal.y(), 0.0, 1e-12);
}

// Two separate bars whose keys swap their places: every inbetween would drive them through each
// other (each follows its own centroid path). Every frame must come out with no overlap and no
// inverted triangle, pushed apart or stopped where they meet, and the keys stay exact.
TEST(InterpOverlapTest, BarsDrivenThroughEachOtherNeverOverlap) {
  Multimesh mesh = GridMesh(8, 2, 0.25);  // 2 x 0.5
  const int n = mesh.num_vertices();
  const std::vector<Triangle> one = mesh.triangles;
  for (Triangle t : one) mesh.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  Points a = mesh.shapes[0];
  for (const Point& p : mesh.shapes[0]) a.push_back(p + Point(0.0, 1.0));  // stacked, 0.5 apart
  Points b;
  for (int v = 0; v < n; ++v) b.push_back(a[v] + Point(0.3, 1.2));        // lower bar goes up
  for (int v = n; v < 2 * n; ++v) b.push_back(a[v] + Point(-0.3, -1.2));  // upper bar down
  mesh.shapes = {a, b};
  const SequenceStats stats = RunSequence(mesh, InbetweenOptions{}, 24);
  EXPECT_EQ(stats.max_overlaps, 0);
  EXPECT_EQ(stats.total_inverted, 0);
  EXPECT_EQ(stats.key_misses, 0);
}

}  // namespace
}  // namespace inbetween::solver
