// Inbetweener (kLinear, kAlexa, kZhu17): keys hit, no collapse where linear collapses, energy
// descent, continuity of large rotations, determinism, cancellation, gauge, errors.
#include "solver/interp/inbetweener.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <thread>

#include "solver/interp/timing.h"
#include "tests/unit/solver/interp/test_meshes.h"

namespace inbetween::solver {
namespace {

using interp_test::Bent;
using interp_test::GridMesh;
using interp_test::MaxDistance;
using interp_test::Rotated;
using interp_test::SignedArea;
using interp_test::Translated;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// A 4x4 grid and the same grid turned by `angle` about (2, 2) and moved.
Multimesh RotationPair(double angle) {
  Multimesh mesh = GridMesh(4, 4);
  mesh.shapes.push_back(Translated(Rotated(mesh.shapes[0], angle, Point(2, 2)), Point(5, -1)));
  return mesh;
}

// A 4 x 1 strip; shape 1 bent into a half circle; shape 2 turned by 90 degrees and moved.
Multimesh StripShapes() {
  Multimesh mesh = GridMesh(8, 2, 0.5);
  mesh.shapes.push_back(Bent(mesh.shapes[0], 4.0, kPi));
  mesh.shapes.push_back(Translated(Rotated(mesh.shapes[0], 0.5 * kPi, Point(0, 0)), Point(3, 3)));
  return mesh;
}

Inbetweener MakeInbetweener(const Multimesh& mesh, InbetweenOptions options) {
  absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, std::move(options));
  EXPECT_TRUE(ib.ok()) << ib.status();
  return *std::move(ib);
}

InbetweenOptions Options(InterpMethod method) {
  InbetweenOptions o;
  o.method = method;
  return o;
}

std::string Name(InterpMethod m) {
  switch (m) {
    case InterpMethod::kLinear:
      return "linear";
    case InterpMethod::kAlexa:
      return "alexa";
    case InterpMethod::kZhu17:
      return "zhu17";
  }
  return "?";
}

// Direction of the grid's bottom edge (vertex 0 -> vertex 4), radians in (-pi, pi].
double EdgeAngle(const Points& x) {
  const Point d = x[4] - x[0];
  return std::atan2(d.y(), d.x());
}

TEST(InterpInbetweenerTest, AllMethodsHitKeys) {
  const Multimesh mesh = StripShapes();
  for (InterpMethod method : {InterpMethod::kLinear, InterpMethod::kAlexa, InterpMethod::kZhu17}) {
    for (bool exact : {false, true}) {
      InbetweenOptions o = Options(method);
      o.exact_keys = exact;
      Inbetweener ib = MakeInbetweener(mesh, o);
      for (int i = 0; i < mesh.num_shapes(); ++i) {
        ExampleWeights w(mesh.num_shapes(), 0.0);
        w[i] = 1.0;
        FrameReport report;
        absl::StatusOr<Frame> f = ib.Solve(w, Frame{}, nullptr, &report);
        ASSERT_TRUE(f.ok()) << f.status();
        if (exact) {
          EXPECT_EQ(f->vertices, mesh.shapes[i]) << Name(method) << " key " << i;
        } else {
          EXPECT_LT(MaxDistance(f->vertices, mesh.shapes[i]), 1e-9) << Name(method) << " " << i;
        }
        EXPECT_EQ(report.inverted, 0);
        EXPECT_LT(report.energy, 1e-18);
        EXPECT_NEAR(report.min_area_ratio, 1.0, 1e-9) << Name(method) << " key " << i;
        EXPECT_NEAR(report.max_area_ratio, 1.0, 1e-9) << Name(method) << " key " << i;
      }
    }
  }
}

TEST(InterpInbetweenerTest, LinearCollapsesAtHalfOf180TurnArapMethodsDoNot) {
  const Multimesh mesh = RotationPair(kPi);
  const ExampleWeights half = {0.5, 0.5};

  Inbetweener linear = MakeInbetweener(mesh, Options(InterpMethod::kLinear));
  FrameReport report;
  absl::StatusOr<Frame> f = linear.Solve(half, Frame{}, nullptr, &report);
  ASSERT_TRUE(f.ok());
  double max_area = 0.0;
  for (const Triangle& t : mesh.triangles) {
    max_area = std::max(max_area, std::abs(SignedArea(f->vertices, t)));
  }
  EXPECT_LT(max_area, 1e-12);  // every triangle degenerates to a point
  EXPECT_GT(report.inverted, 0);
  EXPECT_LT(std::abs(report.min_area_ratio), 1e-9);  // area ratios report the collapse
  EXPECT_LT(std::abs(report.max_area_ratio), 1e-9);

  for (InterpMethod method : {InterpMethod::kAlexa, InterpMethod::kZhu17}) {
    Inbetweener ib = MakeInbetweener(mesh, Options(method));
    f = ib.Solve(half, Frame{}, nullptr, &report);
    ASSERT_TRUE(f.ok()) << f.status();
    EXPECT_EQ(report.inverted, 0) << Name(method);
    for (const Triangle& t : mesh.triangles) {
      EXPECT_NEAR(SignedArea(f->vertices, t), 0.5, 1e-9) << Name(method);  // rigid
    }
    EXPECT_NEAR(report.min_area_ratio, 1.0, 1e-9) << Name(method);
    EXPECT_NEAR(report.max_area_ratio, 1.0, 1e-9) << Name(method);
    EXPECT_NEAR(std::abs(EdgeAngle(f->vertices)), 0.5 * kPi, 1e-9) << Name(method);
    EXPECT_LT(report.energy, 1e-18);
  }
}

TEST(InterpInbetweenerTest, NoInversionThroughLargeTurns) {
  for (double angle : {kPi, 300 * kDeg}) {
    const Multimesh mesh = RotationPair(angle);
    absl::StatusOr<Schedule> schedule = MakeSchedule(2, 24);
    ASSERT_TRUE(schedule.ok());
    for (InterpMethod method : {InterpMethod::kAlexa, InterpMethod::kZhu17}) {
      Inbetweener ib = MakeInbetweener(mesh, Options(method));
      Frame previous;
      for (const FrameTiming& timing : schedule->frames) {
        FrameReport report;
        absl::StatusOr<Frame> f = ib.Solve(timing.weights, previous, nullptr, &report);
        ASSERT_TRUE(f.ok()) << f.status();
        EXPECT_EQ(report.inverted, 0) << Name(method) << " angle " << angle << " t " << timing.time;
        for (const Triangle& t : mesh.triangles) {
          EXPECT_NEAR(SignedArea(f->vertices, t), 0.5, 1e-9);
        }
        previous = *f;
      }
    }
  }
}

// Unwrapped per-frame turn of the bottom edge over a schedule.
std::vector<double> TurnAngles(Inbetweener& ib, const Schedule& schedule) {
  std::vector<double> angles;
  Frame previous;
  for (const FrameTiming& timing : schedule.frames) {
    absl::StatusOr<Frame> f = ib.Solve(timing.weights, previous);
    EXPECT_TRUE(f.ok()) << f.status();
    const double a = EdgeAngle(f->vertices);
    angles.push_back(angles.empty() ? a : UnwrapAngle(a, angles.back()));
    previous = *f;
  }
  return angles;
}

TEST(InterpInbetweenerTest, TwoKeyTurnIsMonotonicWithoutJumps) {
  const Multimesh mesh = RotationPair(300 * kDeg);  // = -60 degrees: the short way round
  absl::StatusOr<Schedule> schedule = MakeSchedule(2, 24);
  ASSERT_TRUE(schedule.ok());
  for (InterpMethod method : {InterpMethod::kAlexa, InterpMethod::kZhu17}) {
    Inbetweener ib = MakeInbetweener(mesh, Options(method));
    const std::vector<double> angles = TurnAngles(ib, *schedule);
    for (size_t k = 1; k < angles.size(); ++k) {
      const double step = angles[k] - angles[k - 1];
      EXPECT_NEAR(step, -60 * kDeg / 23, 1e-9) << Name(method) << " frame " << k;
    }
    EXPECT_NEAR(angles.back() - angles.front(), -60 * kDeg, 1e-9);
  }
}

TEST(InterpInbetweenerTest, ThreeKeysTurnForwardThrough300Degrees) {
  Multimesh mesh = RotationPair(150 * kDeg);
  mesh.shapes.push_back(Rotated(mesh.shapes[0], 300 * kDeg, Point(2, 2)));
  absl::StatusOr<Schedule> schedule = MakeSchedule(3, 25);
  ASSERT_TRUE(schedule.ok());
  for (InterpMethod method : {InterpMethod::kAlexa, InterpMethod::kZhu17}) {
    Inbetweener ib = MakeInbetweener(mesh, Options(method));
    const std::vector<double> angles = TurnAngles(ib, *schedule);
    for (size_t k = 1; k < angles.size(); ++k) {
      EXPECT_NEAR(angles[k] - angles[k - 1], 12.5 * kDeg, 1e-9) << Name(method) << " " << k;
    }
    EXPECT_NEAR(angles.back() - angles.front(), 300 * kDeg, 1e-9);
  }
}

TEST(InterpInbetweenerTest, Zhu17BendingSequenceMovesSmoothly) {
  // Non-rigid keys (strip -> half circle -> turned strip): no frame-to-frame jump.
  const Multimesh mesh = StripShapes();
  absl::StatusOr<Schedule> schedule = MakeSchedule(3, 25);
  ASSERT_TRUE(schedule.ok());
  Inbetweener ib = MakeInbetweener(mesh, Options(InterpMethod::kZhu17));
  Frame previous;
  std::vector<double> steps;
  for (const FrameTiming& timing : schedule->frames) {
    FrameReport report;
    absl::StatusOr<Frame> f = ib.Solve(timing.weights, previous, nullptr, &report);
    ASSERT_TRUE(f.ok());
    EXPECT_EQ(report.inverted, 0);
    if (!previous.vertices.empty()) steps.push_back(MaxDistance(previous.vertices, f->vertices));
    previous = *f;
  }
  for (size_t k = 1; k < steps.size(); ++k) {
    EXPECT_LT(steps[k], 2.5 * steps[k - 1]) << "frame " << k + 1;
    EXPECT_GT(steps[k], steps[k - 1] / 2.5) << "frame " << k + 1;
  }
}

TEST(InterpInbetweenerTest, CancelStopsZhu17BetweenIterations) {
  Multimesh mesh = GridMesh(320, 80, 0.0125);
  mesh.shapes.push_back(Bent(mesh.shapes[0], 4.0, kPi));
  InbetweenOptions o = Options(InterpMethod::kZhu17);
  o.max_iterations = 1000000;
  o.convergence_tolerance = 0.0;
  o.displacement_tolerance = 0.0;
  Inbetweener ib = MakeInbetweener(mesh, o);
  CancelToken cancel;
  std::thread canceller([&cancel] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    cancel.Cancel();
  });
  FrameReport report;
  const absl::StatusOr<Frame> f = ib.Solve({0.5, 0.5}, Frame{}, &cancel, &report);
  canceller.join();
  EXPECT_EQ(f.status().code(), absl::StatusCode::kCancelled) << report.iterations;
}

TEST(InterpInbetweenerTest, Zhu17EnergyDecreasesAndBeatsAlexa) {
  // The reported energy is the kZhu17 objective (blended_arap.h) for every method.
  const Multimesh mesh = StripShapes();
  for (bool anderson : {false, true}) {
    for (const ExampleWeights& w : {ExampleWeights{0.5, 0.5, 0.0}, ExampleWeights{0.2, 0.5, 0.3}}) {
      double previous_energy = 0.0;
      std::vector<double> energies;
      for (int iterations = 0; iterations <= 40; ++iterations) {
        InbetweenOptions o = Options(InterpMethod::kZhu17);
        o.max_iterations = iterations;
        o.convergence_tolerance = 0.0;
        o.displacement_tolerance = 0.0;
        o.anderson = anderson;
        Inbetweener ib = MakeInbetweener(mesh, o);
        FrameReport report;
        absl::StatusOr<Frame> f = ib.Solve(w, Frame{}, nullptr, &report);
        ASSERT_TRUE(f.ok()) << f.status();
        EXPECT_LE(report.iterations, iterations);  // stops early only when the energy stalls
        EXPECT_EQ(report.inverted, 0);
        if (iterations > 0) EXPECT_LE(report.energy, previous_energy * (1 + 1e-12));
        previous_energy = report.energy;
        energies.push_back(report.energy);
      }
      EXPECT_LE(energies.back(), energies.front());

      Inbetweener alexa = MakeInbetweener(mesh, Options(InterpMethod::kAlexa));
      FrameReport alexa_report;
      ASSERT_TRUE(alexa.Solve(w, Frame{}, nullptr, &alexa_report).ok());
      EXPECT_GT(alexa_report.energy, energies.back());
    }
  }
}

TEST(InterpInbetweenerTest, Zhu17ConvergesAndReportsIt) {
  const Multimesh mesh = StripShapes();
  InbetweenOptions o = Options(InterpMethod::kZhu17);
  o.max_iterations = 500;
  Inbetweener ib = MakeInbetweener(mesh, o);
  FrameReport report;
  ASSERT_TRUE(ib.Solve({0.5, 0.5, 0.0}, Frame{}, nullptr, &report).ok());
  EXPECT_GT(report.iterations, 1);
  EXPECT_LT(report.iterations, 500);
  EXPECT_GT(report.energy, 0.0);
  EXPECT_GE(report.seconds, 0.0);
}

TEST(InterpInbetweenerTest, Deterministic) {
  const Multimesh mesh = StripShapes();
  absl::StatusOr<Schedule> schedule = MakeSchedule(3, 13);
  ASSERT_TRUE(schedule.ok());
  std::vector<Points> runs[2];
  for (auto& run : runs) {
    Inbetweener ib = MakeInbetweener(mesh, Options(InterpMethod::kZhu17));
    Frame previous;
    for (const FrameTiming& timing : schedule->frames) {
      absl::StatusOr<Frame> f = ib.Solve(timing.weights, previous);
      ASSERT_TRUE(f.ok());
      run.push_back(f->vertices);
      previous = *f;
    }
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  for (size_t k = 0; k < runs[0].size(); ++k) {
    for (size_t v = 0; v < runs[0][k].size(); ++v) {
      // Bit-identical, not just close.
      EXPECT_EQ(runs[0][k][v].x(), runs[1][k][v].x());
      EXPECT_EQ(runs[0][k][v].y(), runs[1][k][v].y());
    }
  }
}

TEST(InterpInbetweenerTest, CancelledTokenReturnsCancelled) {
  const Multimesh mesh = StripShapes();
  CancelToken cancel;
  cancel.Cancel();
  for (InterpMethod method : {InterpMethod::kLinear, InterpMethod::kAlexa, InterpMethod::kZhu17}) {
    Inbetweener ib = MakeInbetweener(mesh, Options(method));
    EXPECT_EQ(ib.Solve({0.5, 0.5, 0.0}, Frame{}, &cancel).status().code(),
              absl::StatusCode::kCancelled);
    CancelToken live;
    EXPECT_TRUE(ib.Solve({0.5, 0.5, 0.0}, Frame{}, &live).ok());
  }
}

TEST(InterpInbetweenerTest, CentroidFollowsTheExamples) {
  const Multimesh mesh = StripShapes();
  // The gauge's vertex masses: a third of each adjacent triangle's mean area over the examples.
  std::vector<double> mass(mesh.num_vertices(), 0.0);
  for (const Triangle& t : mesh.triangles) {
    double area = 0.0;
    for (const Points& shape : mesh.shapes) area += SignedArea(shape, t);
    for (int v : t) mass[v] += area / (3.0 * mesh.num_shapes());
  }
  auto centroid = [&](const Points& x) {
    Point c(0, 0);
    double m = 0.0;
    for (size_t v = 0; v < x.size(); ++v) {
      c += mass[v] * x[v];
      m += mass[v];
    }
    return Point(c / m);
  };
  const ExampleWeights w = {0.2, 0.5, 0.3};
  Point expected(0, 0);
  for (int i = 0; i < 3; ++i) expected += w[i] * centroid(mesh.shapes[i]);
  for (InterpMethod method : {InterpMethod::kLinear, InterpMethod::kAlexa, InterpMethod::kZhu17}) {
    Inbetweener ib = MakeInbetweener(mesh, Options(method));
    absl::StatusOr<Frame> f = ib.Solve(w, Frame{});
    ASSERT_TRUE(f.ok());
    EXPECT_LT((centroid(f->vertices) - expected).norm(), 1e-12) << Name(method);
  }
}

TEST(InterpInbetweenerTest, SeparateComponentsAndStiffness) {
  // Two squares; in shape 1 the right one has turned by 120 degrees and the left one moved.
  Multimesh mesh = GridMesh(2, 2);
  const Multimesh right = GridMesh(2, 2);
  const int n = mesh.num_vertices();
  for (const Point& p : right.shapes[0]) mesh.shapes[0].push_back(p + Point(5, 0));
  for (Triangle t : right.triangles) mesh.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  Points moved = Translated(GridMesh(2, 2).shapes[0], Point(0, 3));
  for (const Point& p : Rotated(right.shapes[0], 120 * kDeg, Point(1, 1))) {
    moved.push_back(p + Point(5, 0));
  }
  mesh.shapes.push_back(moved);
  InbetweenOptions o = Options(InterpMethod::kZhu17);
  o.stiffness.assign(mesh.triangles.size(), 1.0);
  o.stiffness[0] = 10.0;
  Inbetweener ib = MakeInbetweener(mesh, o);
  FrameReport report;
  absl::StatusOr<Frame> f = ib.Solve({0.5, 0.5}, Frame{}, nullptr, &report);
  ASSERT_TRUE(f.ok()) << f.status();
  EXPECT_EQ(report.inverted, 0);
  EXPECT_LT(report.energy, 1e-18);                           // both components move rigidly
  EXPECT_LT((f->vertices[0] - Point(0, 1.5)).norm(), 1e-9);  // left square: halfway up
  const Point d = f->vertices[n + 2] - f->vertices[n];       // right square: turned 60 deg
  EXPECT_NEAR(std::atan2(d.y(), d.x()), 60 * kDeg, 1e-9);
  f = ib.Solve({0.0, 1.0}, Frame{});
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->vertices, mesh.shapes[1]);
}

TEST(InterpInbetweenerTest, RejectsBadInput) {
  const Multimesh mesh = StripShapes();
  Inbetweener ib = MakeInbetweener(mesh, Options(InterpMethod::kZhu17));
  EXPECT_EQ(ib.Solve({0.5, 0.5}, Frame{}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ib.Solve({0.5, 0.6, 0.0}, Frame{}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ib.Solve({-0.5, 1.5, 0.0}, Frame{}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ib.Solve({0.5, 0.5, 0.0}, Frame{{Point(0, 0)}}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ib.Solve({std::nan(""), 0.5, 0.5}, Frame{}).status().code(),
            absl::StatusCode::kInvalidArgument);

  Multimesh flipped = mesh;
  std::swap(flipped.shapes[1][0], flipped.shapes[1][20]);
  absl::StatusOr<Inbetweener> bad = Inbetweener::Create(flipped, InbetweenOptions{});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("shape 1"), std::string::npos) << bad.status();

  Multimesh extra = mesh;
  for (Points& shape : extra.shapes) shape.push_back(Point(9, 9));
  bad = Inbetweener::Create(extra, InbetweenOptions{});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("vertex"), std::string::npos) << bad.status();

  Multimesh ragged = mesh;
  ragged.shapes[2].pop_back();
  EXPECT_FALSE(Inbetweener::Create(ragged, InbetweenOptions{}).ok());

  InbetweenOptions o;
  o.stiffness = {1.0, 2.0};
  EXPECT_FALSE(Inbetweener::Create(mesh, o).ok());
  EXPECT_FALSE(Inbetweener::Create(Multimesh{}, InbetweenOptions{}).ok());
}

}  // namespace
}  // namespace inbetween::solver
