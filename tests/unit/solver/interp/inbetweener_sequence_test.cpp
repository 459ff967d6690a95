// Inbetweener properties over frames and iterations: stiffness regions under keys that
// genuinely conflict, cohesive hysteresis across a frame sequence, monotone descent for
// alpha != 1/2, timing curves through the solver, and the accuracy of the default stopping rule.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "solver/interp/blended_arap.h"
#include "solver/interp/inbetweener.h"
#include "solver/interp/timing.h"
#include "tests/unit/solver/interp/test_meshes.h"

namespace inbetween::solver {
namespace {

using interp_test::BentAboutCentre;
using interp_test::GridMesh;
using interp_test::MaxDistance;
using interp_test::SlitMesh;

constexpr double kPi = std::numbers::pi;

// A 4 x 1 bar with three keys: straight, bent into a half circle about its centre line, and
// sheared (x + 0.6 y). Blending the bend with the shear asks for a rotation field that varies
// along the bar together with an off-diagonal stretch, which no deformation has (the blended
// targets are not a gradient field): the keys conflict and some triangles must give.
Multimesh ConflictingBar() {
  Multimesh mesh = GridMesh(16, 4, 0.25);
  mesh.shapes.push_back(BentAboutCentre(mesh.shapes[0], 4.0, kPi));
  Points sheared;
  for (const Point& p : mesh.shapes[0]) sheared.emplace_back(p.x() + 0.6 * p.y(), p.y());
  mesh.shapes.push_back(sheared);
  return mesh;
}

// What `region` gives up to the rest of the mesh: the unit-stiffness blended ARAP energy of its
// triangles at x minus the least energy they reach when the region is solved on its own (its
// own best compromise between the keys).
double RegionExcess(const Multimesh& mesh, const std::vector<int>& region, const Points& x,
                    const std::vector<double>& w) {
  Multimesh sub;
  sub.shapes.resize(mesh.num_shapes());
  std::vector<int> index(mesh.num_vertices(), -1);
  Points corners;
  for (int t : region) {
    Triangle tri;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k];
      if (index[v] < 0) {
        index[v] = static_cast<int>(corners.size());
        corners.push_back(x[v]);
        for (int i = 0; i < mesh.num_shapes(); ++i) sub.shapes[i].push_back(mesh.shapes[i][v]);
      }
      tri[k] = index[v];
    }
    sub.triangles.push_back(tri);
  }
  absl::StatusOr<BlendedArap> energy = BlendedArap::Create(sub.triangles, sub.shapes);
  InbetweenOptions o;
  o.max_iterations = 2000;
  o.displacement_tolerance = 1e-12;
  o.convergence_tolerance = 0.0;
  absl::StatusOr<Inbetweener> alone = Inbetweener::Create(sub, o);
  EXPECT_TRUE(energy.ok() && alone.ok());
  FrameReport report;
  EXPECT_TRUE(alone->Solve(w, Frame{}, nullptr, &report).ok());
  return energy->Value(ToCoords(corners), w) - report.energy;
}

TEST(InterpSequenceTest, StifferRegionGivesLessWhereKeysConflict) {
  const Multimesh mesh = ConflictingBar();
  const std::vector<double> w = {0.0, 0.5, 0.5};
  std::vector<int> left, right;
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    double cx = 0.0;
    for (int v : mesh.triangles[t]) cx += mesh.shapes[0][v].x() / 3.0;
    (cx < 2.0 ? left : right).push_back(t);
  }
  auto solve = [&](double left_kappa) {
    InbetweenOptions o;
    o.max_iterations = 500;
    o.displacement_tolerance = 1e-9;
    o.stiffness.assign(mesh.triangles.size(), 1.0);
    for (int t : left) o.stiffness[t] = left_kappa;
    absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, o);
    EXPECT_TRUE(ib.ok()) << ib.status();
    FrameReport report;
    absl::StatusOr<Frame> f = ib->Solve(w, Frame{}, nullptr, &report);
    EXPECT_TRUE(f.ok()) << f.status();
    EXPECT_EQ(report.inverted, 0);
    return f->vertices;
  };
  const Points uniform = solve(1.0);
  const Points stiff = solve(20.0);
  const double uniform_left = RegionExcess(mesh, left, uniform, w);
  const double uniform_right = RegionExcess(mesh, right, uniform, w);
  const double stiff_left = RegionExcess(mesh, left, stiff, w);
  const double stiff_right = RegionExcess(mesh, right, stiff, w);
  // The conflict is real: with uniform stiffness both halves give up energy to each other.
  EXPECT_GT(uniform_left, 1e-6);
  EXPECT_GT(uniform_right, 1e-6);
  // The stiff half stays close to its own best shape; the soft half takes up the mismatch.
  EXPECT_LT(stiff_left, 0.1 * uniform_left);
  EXPECT_GT(stiff_right, uniform_right);
}

// Separated cohesive edges per frame along `w1` (weights {1 - w1, w1}), frames solved in order.
std::vector<int> SeparatedAlong(const Multimesh& mesh, InbetweenOptions o,
                                const std::vector<double>& w1) {
  absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, o);
  EXPECT_TRUE(ib.ok()) << ib.status();
  FrameSequence sequence(&*ib);
  std::vector<int> separated;
  for (double w : w1) {
    FrameReport report;
    absl::StatusOr<Frame> f = sequence.Next({1.0 - w, w}, nullptr, &report);
    EXPECT_TRUE(f.ok()) << f.status();
    EXPECT_EQ(report.inverted, 0);
    separated.push_back(report.separated_edges);
  }
  return separated;
}

TEST(InterpSequenceTest, CohesiveEdgeNearTauDoesNotFlicker) {
  const Multimesh mesh = SlitMesh(8, 6, 4, 0.25, 0.3, 0.0);  // opens in shape 1
  InbetweenOptions o;
  o.lambda = 1.0;
  o.tau = 1e-4;
  o.max_iterations = 200;
  o.displacement_tolerance = 1e-8;
  // A slow ramp finds the weight at which the first edge separates.
  std::vector<double> ramp;
  for (int k = 0; k <= 40; ++k) ramp.push_back(0.05 + 0.9 * k / 40.0);
  const std::vector<int> ramp_separated = SeparatedAlong(mesh, o, ramp);
  int first = -1;
  for (size_t k = 0; k < ramp.size(); ++k) {
    if (ramp_separated[k] > 0) {
      first = static_cast<int>(k);
      break;
    }
  }
  ASSERT_GT(first, 0) << "the zone must start closed and open within the ramp";
  ASSERT_GT(ramp_separated.back(), 0);
  // Then the weights wobble around that point, one ramp step either way, for 30 frames.
  std::vector<double> wobble(ramp.begin(), ramp.begin() + first);
  for (int k = 0; k < 30; ++k) wobble.push_back(ramp[first] + (k % 2 == 0 ? 1 : -1) * 0.9 / 40);
  auto changes = [&](const std::vector<int>& separated) {
    int n = 0;
    for (size_t k = first + 1; k < separated.size(); ++k) n += separated[k] != separated[k - 1];
    return n;
  };
  const std::vector<int> steady = SeparatedAlong(mesh, o, wobble);
  EXPECT_LE(changes(steady), 1) << "edges flicker between bonded and separated";
  EXPECT_GT(steady.back(), 0);
  // Without hysteresis the same wobble does flicker (so the test can see flicker at all).
  o.hysteresis = 0.0;
  EXPECT_GT(changes(SeparatedAlong(mesh, o, wobble)), 5);
}

TEST(InterpSequenceTest, EnergyNeverIncreasesOverIterationsForAnyAlpha) {
  // Opening and shearing keys, capped edges (small tau): every branch of W_C is exercised.
  Multimesh mesh = SlitMesh(8, 6, 4, 0.25, 0.3, 0.3);
  ASSERT_EQ(mesh.num_shapes(), 3);
  for (double alpha : {0.1, 0.5, 0.9}) {
    for (bool anderson : {false, true}) {
      double previous = std::numeric_limits<double>::infinity();
      for (int k = 0; k <= 25; ++k) {
        InbetweenOptions o;
        o.lambda = 20.0;
        o.tau = 0.002;
        o.alpha = alpha;
        o.anderson = anderson;
        o.warm_start = false;
        o.prevent_overlap = false;
        o.max_iterations = k;
        o.displacement_tolerance = 0.0;
        o.convergence_tolerance = 0.0;
        absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, o);
        ASSERT_TRUE(ib.ok()) << ib.status();
        FrameReport report;
        ASSERT_TRUE(ib->Solve({0.2, 0.4, 0.4}, Frame{}, nullptr, &report).ok());
        EXPECT_LE(report.energy, previous) << "alpha " << alpha << ", iteration " << k;
        previous = report.energy;
      }
    }
  }
}

TEST(InterpSequenceTest, TimingCurvesDriveTheSolverAndKeepKeysExact) {
  Multimesh mesh = GridMesh(16, 4, 0.25);
  mesh.shapes.push_back(BentAboutCentre(mesh.shapes[0], 4.0, kPi));
  mesh.shapes.push_back(BentAboutCentre(mesh.shapes[0], 4.0, -0.5 * kPi));
  TimingOptions timing;
  timing.curve = TimingCurve::kCatmullRom;
  timing.easing = {Easing::kEaseIn, Easing::kEaseOut};
  absl::StatusOr<Schedule> schedule = MakeSchedule(3, 31, {0.0, 0.3, 1.0}, timing);
  ASSERT_TRUE(schedule.ok()) << schedule.status();
  absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, InbetweenOptions{});
  ASSERT_TRUE(ib.ok());
  FrameSequence sequence(&*ib);
  for (int f = 0; f < 31; ++f) {
    FrameReport report;
    absl::StatusOr<Frame> frame = sequence.Next(schedule->frames[f].weights, nullptr, &report);
    ASSERT_TRUE(frame.ok()) << frame.status();
    EXPECT_EQ(report.inverted, 0) << f;
    EXPECT_EQ(report.overlaps, 0) << f;
    for (int i = 0; i < 3; ++i) {
      if (schedule->keys[i] == f) EXPECT_EQ(frame->vertices, mesh.shapes[i]);
    }
  }
}

TEST(InterpSequenceTest, DefaultStoppingRuleIsCloseToTheConvergedFrame) {
  // Sequential playback with the default tolerances against frames solved to convergence: the
  // largest vertex error stays below 1e-3 of the bar's length (a pixel at 1000 pixels).
  Multimesh mesh = GridMesh(32, 8, 0.125);
  mesh.shapes.push_back(BentAboutCentre(mesh.shapes[0], 4.0, 1.5 * kPi));
  absl::StatusOr<Schedule> schedule = MakeSchedule(2, 13);
  ASSERT_TRUE(schedule.ok());
  InbetweenOptions tight;
  tight.max_iterations = 2000;
  tight.displacement_tolerance = 1e-11;
  tight.convergence_tolerance = 0.0;
  absl::StatusOr<Inbetweener> fast = Inbetweener::Create(mesh, InbetweenOptions{});
  absl::StatusOr<Inbetweener> converged = Inbetweener::Create(mesh, tight);
  ASSERT_TRUE(fast.ok() && converged.ok());
  FrameSequence sequence(&*fast);
  for (const FrameTiming& timing : schedule->frames) {
    absl::StatusOr<Frame> f = sequence.Next(timing.weights);
    ASSERT_TRUE(f.ok());
    absl::StatusOr<Frame> reference = converged->Solve(timing.weights, *f);
    ASSERT_TRUE(reference.ok());
    EXPECT_LT(MaxDistance(f->vertices, reference->vertices), 1e-3 * 4.0) << timing.time;
  }
}

TEST(InterpSequenceTest, FramesAreBitIdenticalForEveryThreadCount) {
  // Large enough (32768 triangles, 16705 rows) for the chunked local step, the gathered
  // right-hand side and the per-column substitutions to run in parallel.
  Multimesh mesh = GridMesh(256, 64, 4.0 / 256);
  mesh.shapes.push_back(BentAboutCentre(mesh.shapes[0], 4.0, kPi));
  std::vector<std::vector<Points>> runs;
  for (int threads : {1, 2, 3}) {
    InbetweenOptions o;
    o.threads = threads;
    absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, o);
    ASSERT_TRUE(ib.ok()) << ib.status();
    FrameSequence sequence(&*ib);
    runs.emplace_back();
    for (double w : {0.0, 0.3, 0.6}) {
      absl::StatusOr<Frame> f = sequence.Next({1.0 - w, w});
      ASSERT_TRUE(f.ok()) << f.status();
      runs.back().push_back(f->vertices);
    }
  }
  for (size_t r = 1; r < runs.size(); ++r) {
    for (size_t k = 0; k < runs[0].size(); ++k) EXPECT_EQ(runs[r][k], runs[0][k]) << r << " " << k;
  }
}

}  // namespace
}  // namespace inbetween::solver
