// Tests for the comesh inner loop: descent, no inversion at any iterate, conformal limit,
// improvement on square -> hexagon, cancellation, determinism, input validation, resuming from a
// checkpoint.
#include "solver/comesh/comesh_optimizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <thread>

#include "absl/strings/str_cat.h"
#include "solver/comesh/comesh_objective.h"
#include "solver/comesh/comesh_pairing.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"
#include "tests/unit/solver/comesh/comesh_boundary_expect.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace inbetween::solver {
namespace {

double TotalArea(const std::vector<Triangle>& triangles, const Points& x) {
  double area = 0.0;
  for (const Triangle& t : triangles) {
    const Point ab = x[t[1]] - x[t[0]], ac = x[t[2]] - x[t[0]];
    area += 0.5 * (ab.x() * ac.y() - ab.y() * ac.x());
  }
  return area;
}

// k even: see SquareGrid (no corner triangle with three vertices on one hexagon side).
Multimesh SquareToHexagon(int k) {
  Multimesh m = testing::SquareGrid(k);
  m.shapes.push_back(testing::TutteHexagon(m));
  return m;
}

// Over every accepted iterate of a run on the fixed topology of `m` (max_outer = 0): the
// inverted triangles of every shape and the iterates whose objective, evaluated afresh, rose
// above the one before. Run optimizes with on_iterate set to count them.
// An axis-aligned ellipse drawn as a 96-point outline.
Drawing Ellipse(Point center, double a, double b) {
  Drawing d;
  Points outline;
  for (int k = 0; k < 96; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 96.0;
    outline.push_back(center + Point(a * std::cos(t), b * std::sin(t)));
  }
  d.outlines.push_back({outline});
  return d;
}

// BuildMultimesh with `boundary_vertices` per shape (and max_edge_relative if > 0).
absl::StatusOr<Multimesh> BuildDrawings(const std::vector<Drawing>& drawings, int boundary_vertices,
                                        double max_edge_relative = 0.0) {
  MultimeshOptions build;
  build.boundary_vertices = boundary_vertices;
  if (max_edge_relative > 0.0) build.max_edge_relative = max_edge_relative;
  return BuildMultimesh(drawings, build);
}

struct IterateAudit {
  int iterates = 0;
  int inverted = 0;
  int increases = 0;

  absl::StatusOr<Multimesh> Run(const Multimesh& m, ComeshOptions options, ComeshReport* report) {
    Install(m, &options);
    return OptimizeComesh(m, options, nullptr, nullptr, report);
  }

 private:
  void Install(const Multimesh& m, ComeshOptions* options) {
    auto objective = std::make_shared<ComeshObjective>(
        ComeshObjective::Create(m.triangles, m.shapes, options->map_weight).value());
    auto previous = std::make_shared<double>(objective->Evaluate(m.shapes));
    options->on_iterate = [this, objective, previous, triangles = m.triangles](
                              int, const std::vector<Points>& shapes) {
      ++iterates;
      for (const Points& x : shapes) inverted += testing::CountNonPositive(triangles, x);
      const double f = objective->Evaluate(shapes);
      if (!(f <= *previous)) ++increases;
      *previous = f;
    };
  }
};

TEST(ComeshOptimizerTest, DecreasesObjectiveWithoutInvertingAnyIterate) {
  const Multimesh m = SquareToHexagon(10);
  ComeshOptions options;
  options.max_outer = 0;  // the inner loop alone: topology (and thus the objective) fixed
  // The hexagon's boundary is the square's, placed by arc length: four of its corners fall
  // between vertices, whose turns (up to 60 degrees) are then split between two vertices, some
  // below outline_corner_degrees. Straight-run sliding alone keeps the domains exactly, which
  // this test checks (outline sliding: CurvedOutlinesSlideAlongTheirPolylines).
  options.slide_outline = false;
  IterateAudit audit;
  ComeshReport report;
  auto out = audit.Run(m, options, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GT(audit.iterates, 5);
  EXPECT_EQ(audit.iterates, report.inner);
  EXPECT_EQ(audit.inverted, 0);
  EXPECT_EQ(audit.increases, 0);
  EXPECT_LT(report.objective_after, report.objective_before);
  EXPECT_LT(report.map_energy, report.map_energy_before);
  EXPECT_EQ(report.vertices_before, m.num_vertices());
  EXPECT_EQ(report.vertices_after, m.num_vertices());
  // Sliding keeps every shape's domain: same total area, square boundary stays on the square.
  for (int s = 0; s < m.num_shapes(); ++s) {
    EXPECT_NEAR(TotalArea(m.triangles, out->shapes[s]), TotalArea(m.triangles, m.shapes[s]), 1e-12);
  }
  int moved = 0;
  for (int v : m.boundary) {
    const Point p = out->shapes[0][v];
    EXPECT_NEAR(std::min({p.x(), p.y(), 1.0 - p.x(), 1.0 - p.y()}), 0.0, 1e-12);
    moved += p != m.shapes[0][v];
  }
  EXPECT_GT(moved, 0);
  for (const Point& corner : {Point(0, 0), Point(1, 0), Point(1, 1), Point(0, 1)}) {
    bool found = false;
    for (int v : m.boundary) found |= out->shapes[0][v] == corner;
    EXPECT_TRUE(found) << corner.transpose();
  }
}

TEST(ComeshOptimizerTest, FixedBoundaryWhenSlidingIsOff) {
  const Multimesh m = SquareToHexagon(8);
  ComeshOptions options;
  options.slide_boundary = false;
  ComeshReport report;
  auto out = OptimizeComesh(m, options, nullptr, nullptr, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_LT(report.objective_after, report.objective_before);
  for (int s = 0; s < m.num_shapes(); ++s) {
    for (int v : m.boundary) EXPECT_EQ(out->shapes[s][v], m.shapes[s][v]);
  }
}

TEST(ComeshOptimizerTest, SimilarShapesReachConformalMapEnergy) {
  Multimesh m = testing::SquareGrid(8);
  const Points distorted = testing::SmoothlyDistorted(m.shapes[0], 0.09);
  m.shapes = {m.shapes[0], testing::Similar(distorted, 0.5, 2.5, Point(4, -1))};
  ComeshReport report;
  auto out = OptimizeComesh(m, ComeshOptions{}, nullptr, nullptr, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GT(report.map_energy_before, 2.02);
  EXPECT_LT(report.map_energy, 2.001) << report.stop_reason;
  EXPECT_GE(report.map_energy, 2.0 - 1e-12);
}

TEST(ComeshOptimizerTest, SquareToHexagonImprovesMapAndKeepsMeshSane) {
  const Multimesh m = SquareToHexagon(12);
  // The Hessian model with and without its MIPS damping, and BCQN's Laplacian (with and without
  // the Laplacian itself).
  for (int variant = 0; variant < 4; ++variant) {
    ComeshOptions options;
    options.hessian_preconditioner = variant < 2;
    options.mips_damping = variant == 1 ? 0.0 : options.mips_damping;
    options.laplacian_preconditioner = variant != 3;
    ComeshReport report;
    auto out = OptimizeComesh(m, options, nullptr, nullptr, &report);
    ASSERT_TRUE(out.ok()) << out.status();
    EXPECT_LT(report.map_energy, report.map_energy_before - 0.01) << "variant " << variant;
    EXPECT_LT(report.mesh_energy, 1.5);
    for (const Points& x : out->shapes) EXPECT_EQ(testing::CountNonPositive(out->triangles, x), 0);
  }
}

TEST(ComeshOptimizerTest, ThreeShapeCycle) {
  Multimesh m = SquareToHexagon(8);
  m.shapes.push_back(testing::SmoothlyDistorted(m.shapes[0], -0.08));
  ComeshReport report;
  auto out = OptimizeComesh(m, ComeshOptions{}, nullptr, nullptr, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_LT(report.objective_after, report.objective_before);
  for (const Points& x : out->shapes) EXPECT_EQ(testing::CountNonPositive(m.triangles, x), 0);
}

TEST(ComeshOptimizerTest, Deterministic) {
  const Multimesh m = SquareToHexagon(8);
  ComeshOptions options;
  options.max_iterations = 40;
  auto a = OptimizeComesh(m, options, nullptr, nullptr, nullptr);
  auto b = OptimizeComesh(m, options, nullptr, nullptr, nullptr);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->shapes, b->shapes);
}

TEST(ComeshOptimizerTest, CancelStopsWithCancelled) {
  const Multimesh m = SquareToHexagon(10);
  CancelToken cancel;
  int calls = 0;
  ProgressFn progress = [&](const std::string& stage, double fraction, const std::string&) {
    EXPECT_EQ(stage, "comesh");
    EXPECT_GE(fraction, 0.0);
    EXPECT_LE(fraction, 1.0);
    if (++calls == 3) cancel.Cancel();
  };
  auto out = OptimizeComesh(m, ComeshOptions{}, &cancel, progress, nullptr);
  EXPECT_TRUE(absl::IsCancelled(out.status())) << out.status();
  EXPECT_EQ(calls, 3);
}

// A token set before the call: CANCELLED before any iteration, with either preconditioner (their
// set-ups poll it too; SparseCholesky's own tests cover the polls inside a factorization, and
// `scripts/bench comesh-scaling --cancel-trials N` measures the latency).
TEST(ComeshOptimizerTest, CancelledBeforeTheCallStopsBeforeAnyWork) {
  const Multimesh m = SquareToHexagon(10);
  CancelToken cancel;
  cancel.Cancel();
  for (const bool hessian : {true, false}) {
    ComeshOptions options;
    options.hessian_preconditioner = hessian;
    options.laplacian_preconditioner = true;
    int calls = 0;
    ProgressFn progress = [&](const std::string&, double, const std::string&) { ++calls; };
    auto out = OptimizeComesh(m, options, &cancel, progress, nullptr);
    EXPECT_TRUE(absl::IsCancelled(out.status())) << out.status();
    EXPECT_NE(out.status().message().find("at start"), std::string::npos) << out.status();
    EXPECT_EQ(calls, 0);
  }
}

// Every Hessian analysis on a helper thread (background_analysis_unknowns = 1, as blocks of 65,536
// unknowns and more get by default): the same multimesh bit for bit, and cancels from another
// thread at many moments (some inside an analysis, whose helper then finishes on its own after
// OptimizeComesh returned) answer CANCELLED or finish, never anything else (and under the
// sanitizer builds, touch nothing freed).
TEST(ComeshOptimizerTest, AnalysisOnAHelperThreadGivesTheSameResultAndCancels) {
  const Multimesh m = SquareToHexagon(12);
  ComeshOptions options;
  options.threads = 2;
  const absl::StatusOr<Multimesh> inline_run = OptimizeComesh(m, options, nullptr, {}, nullptr);
  ASSERT_TRUE(inline_run.ok()) << inline_run.status();
  options.background_analysis_unknowns = 1;
  CancelToken never;
  const absl::StatusOr<Multimesh> helper_run = OptimizeComesh(m, options, &never, {}, nullptr);
  ASSERT_TRUE(helper_run.ok()) << helper_run.status();
  EXPECT_EQ(helper_run->shapes, inline_run->shapes);
  EXPECT_EQ(helper_run->triangles, inline_run->triangles);
  int cancelled = 0;
  for (int delay_us = 0; delay_us < 20000; delay_us += 1000) {
    CancelToken cancel;
    std::thread canceller([&] {
      std::this_thread::sleep_for(std::chrono::microseconds(delay_us));
      cancel.Cancel();
    });
    const absl::StatusOr<Multimesh> out = OptimizeComesh(m, options, &cancel, {}, nullptr);
    canceller.join();
    if (out.ok()) continue;
    EXPECT_TRUE(absl::IsCancelled(out.status())) << out.status();
    ++cancelled;
  }
  EXPECT_GT(cancelled, 0);
}

// Cancels spread over a whole run with the shape-block Hessian on two threads (every phase of an
// iteration polls: the two-loop recursion, the solves, the Hessian product, curing, the step
// bound, the trials, the pair update, and the set-up's layout, assembly and factorizations):
// each answer is CANCELLED or exactly the uncancelled result, never another error or mesh.
TEST(ComeshOptimizerTest, CancelAtAnyMomentAnswersCancelledOrTheSameResult) {
  const Multimesh m = SquareToHexagon(16);
  ComeshOptions options;
  options.threads = 2;
  CancelToken never;
  const auto start = std::chrono::steady_clock::now();
  const absl::StatusOr<Multimesh> whole = OptimizeComesh(m, options, &never, {}, nullptr);
  const std::chrono::duration<double> seconds = std::chrono::steady_clock::now() - start;
  ASSERT_TRUE(whole.ok()) << whole.status();
  int cancelled = 0;
  for (int trial = 0; trial < 24; ++trial) {
    CancelToken cancel;
    std::thread canceller([&] {
      std::this_thread::sleep_for(seconds * trial / 20);
      cancel.Cancel();
    });
    const absl::StatusOr<Multimesh> out = OptimizeComesh(m, options, &cancel, {}, nullptr);
    canceller.join();
    if (out.ok()) {
      EXPECT_EQ(out->shapes, whole->shapes) << "trial " << trial;
      EXPECT_EQ(out->triangles, whole->triangles) << "trial " << trial;
      continue;
    }
    EXPECT_TRUE(absl::IsCancelled(out.status())) << "trial " << trial << ": " << out.status();
    ++cancelled;
  }
  EXPECT_GT(cancelled, 0);
  RecordProperty("cancelled", cancelled);
}

TEST(ComeshOptimizerTest, RejectsInvertedInputNamingShape) {
  Multimesh m = SquareToHexagon(4);
  std::swap(m.shapes[1][6], m.shapes[1][7]);
  auto out = OptimizeComesh(m, ComeshOptions{}, nullptr, nullptr, nullptr);
  ASSERT_EQ(out.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(out.status().message().find("shape 1"), std::string::npos) << out.status();
}

TEST(ComeshOptimizerTest, NothingFreeReturnsInput) {
  Multimesh m = testing::SquareGrid(1);
  m.shapes.push_back(testing::Similar(m.shapes[0], 0.1, 2.0, Point(0, 0)));
  ComeshReport report;
  auto out = OptimizeComesh(m, ComeshOptions{}, nullptr, nullptr, &report);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->shapes, m.shapes);
  EXPECT_EQ(report.stop_reason, "no_free");
}

// A real multimesh (BuildMultimesh) from generated polygons: unit square -> regular hexagon.
absl::StatusOr<Multimesh> BuiltSquareToHexagon(int boundary_vertices,
                                               double max_edge_relative = -1.0) {
  Drawing square, hexagon;
  square.outlines.push_back({{Point(0, 0), Point(1, 0), Point(1, 1), Point(0, 1)}});
  Points hex;
  for (int k = 0; k < 6; ++k) {
    const double a = k * std::numbers::pi / 3.0;
    hex.push_back(Point(0.5, 0.5) + 0.6 * Point(std::cos(a), std::sin(a)));
  }
  hexagon.outlines.push_back({hex});
  MultimeshOptions options;
  options.boundary_vertices = boundary_vertices;
  if (max_edge_relative > 0.0) options.max_edge_relative = max_edge_relative;
  return BuildMultimesh({square, hexagon}, options);
}

TEST(ComeshOptimizerTest, OuterLoopOnRealSquareToHexagonDropsVerticesAndStaysValid) {
  auto m = BuiltSquareToHexagon(48);
  ASSERT_TRUE(m.ok()) << m.status();
  ComeshOptions options;
  int iterates = 0;
  options.on_iterate = [&](int, const std::vector<Points>&) { ++iterates; };
  ComeshReport report;
  auto out = OptimizeComesh(*m, options, nullptr, nullptr, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GT(report.outer, 0);
  EXPECT_EQ(report.vertices_before, m->num_vertices());
  EXPECT_EQ(report.vertices_after, out->num_vertices());
  EXPECT_LT(report.vertices_after, report.vertices_before);
  EXPECT_TRUE(ValidateMultimesh(*out).ok()) << ValidateMultimesh(*out);
  for (const Points& x : out->shapes) EXPECT_EQ(CountInverted(out->triangles, x), 0);
  // Objective non-increasing across inner runs and topology passes.
  ASSERT_GE(report.objective_trace.size(), 2u);
  double previous = report.objective_before;
  for (double f : report.objective_trace) {
    EXPECT_LE(f, previous * (1 + 1e-12));
    previous = f;
  }
  EXPECT_EQ(report.objective_trace.back(), report.objective_after);
  EXPECT_LT(report.map_energy, report.map_energy_before);
  EXPECT_LT(report.mesh_energy, report.mesh_energy_before);
  // The boundary is the same point set (sliders move along their straight side, boundary
  // collapses drop some of them; corners stay), and its loops are kept.
  ASSERT_EQ(out->boundary_loops.size(), 1u);
  testing::ExpectBoundaryKept(*m, *out);
  EXPECT_EQ(iterates, report.inner);
}

// S-Table 1's kind of start (the paper meshes the boundary samples by quality refinement only):
// a dense boundary and a graded interior carry needless vertices, and the outer loop removes a
// large share of them (the paper: 467 -> 345) while both energies fall and nothing inverts.
TEST(ComeshOptimizerTest, GradedStartLosesAQuarterOfItsVertices) {
  auto m = BuiltSquareToHexagon(120, /*max_edge_relative=*/1.0);
  ASSERT_TRUE(m.ok()) << m.status();
  ASSERT_GT(m->num_vertices(), 180);
  ComeshReport report;
  auto out = OptimizeComesh(*m, ComeshOptions{}, nullptr, nullptr, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_LT(report.vertices_after, 0.75 * report.vertices_before)
      << report.vertices_before << " -> " << report.vertices_after;
  EXPECT_LT(report.map_energy, report.map_energy_before);
  EXPECT_LT(report.mesh_energy, report.mesh_energy_before);
  EXPECT_TRUE(ValidateMultimesh(*out).ok()) << ValidateMultimesh(*out);
  for (const Points& x : out->shapes) EXPECT_EQ(CountInverted(out->triangles, x), 0);
  testing::ExpectBoundaryKept(*m, *out);
}

// A mouth closed in one drawing and open in the other (an opening): after the outer loop the
// multimesh still has its two boundary loops, its cohesive edges and the list of shapes where
// they are closed, all consistent (ValidateMultimesh checks loops and collocation).
TEST(ComeshOptimizerTest, OuterLoopKeepsLoopsAndCohesiveEdgesOfAnOpening) {
  Drawing closed = testing::RegularPolygon(48, 10.0, Point(0, 0));
  Drawing open = closed;
  closed.openings = {{{-5, 2}, {0, 2.5}, {5, 2}}};
  open.outlines.push_back({{{-5, 2}, {0, 0}, {5, 2}, {0, 5}}});  // the open mouth
  auto m = BuildMultimesh({closed, open}, {});
  ASSERT_TRUE(m.ok()) << m.status();
  ASSERT_EQ(m->boundary_loops.size(), 2u);
  ASSERT_FALSE(m->cohesive_edges.empty());
  ComeshReport report;
  const ComeshOptions options;  // outline sliding on: the 48-gon's vertices slide
  auto out = OptimizeComesh(*m, options, nullptr, nullptr, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GT(report.collapses + report.flips, 0);  // the passes changed the mesh
  EXPECT_TRUE(ValidateMultimesh(*out).ok()) << ValidateMultimesh(*out);
  ASSERT_EQ(out->boundary_loops.size(), 2u);
  testing::ExpectBoundaryKept(*m, *out, options.outline_corner_degrees);
  EXPECT_EQ(out->cohesive_edges.size(), m->cohesive_edges.size());
  EXPECT_EQ(out->cohesive_closed, m->cohesive_closed);
  // Cohesive-edge vertices are pinned: the same places, in the same order.
  for (int s = 0; s < out->num_shapes(); ++s) {
    for (size_t c = 0; c < m->cohesive_edges.size(); ++c) {
      for (int k = 0; k < 4; ++k) {
        EXPECT_EQ(out->shapes[s][out->cohesive_edges[c][k]], m->shapes[s][m->cohesive_edges[c][k]]);
      }
    }
  }
}

TEST(ComeshOptimizerTest, ResultDoesNotDependOnThreadCount) {
  // 2 * 66^2 = 8712 triangles: above the parallel cut-off, so threads really run.
  Multimesh m = SquareToHexagon(66);
  ComeshOptions options;
  options.max_iterations = 15;
  options.max_outer = 1;
  options.outer_inner_iterations = 5;
  ComeshReport r1, r2;
  options.threads = 1;
  auto a = OptimizeComesh(m, options, nullptr, nullptr, &r1);
  options.threads = 2;
  auto b = OptimizeComesh(m, options, nullptr, nullptr, &r2);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->triangles, b->triangles);
  EXPECT_EQ(a->shapes, b->shapes);
  EXPECT_EQ(r1.objective_after, r2.objective_after);
  EXPECT_EQ(r1.inner, r2.inner);
}

// The same with outline sliding's second stage (curved drawings, three shapes: the Laplacian
// preconditioner with its floating components).
TEST(ComeshOptimizerTest, SlidingResultDoesNotDependOnThreadCount) {
  absl::StatusOr<Multimesh> m =
      BuildDrawings({Ellipse(Point(0.5, 0.5), 0.5, 0.5), Ellipse(Point(0.5, 0.5), 0.9, 0.3),
                     Ellipse(Point(0.5, 0.5), 0.3, 0.8)},
                    160, 0.02);
  ASSERT_TRUE(m.ok()) << m.status();
  ASSERT_GT(m->triangles.size(), 4096u);  // more than one chunk: threads really run
  ComeshOptions options;
  options.max_iterations = 15;
  options.max_outer = 2;
  options.outer_inner_iterations = 5;
  int sliding_stages = 0;
  const ProgressFn progress = [&](const std::string&, double, const std::string& message) {
    sliding_stages += message == "outline sliding";
  };
  ComeshReport r1, r2;
  options.threads = 1;
  auto a = OptimizeComesh(*m, options, nullptr, progress, &r1);
  options.threads = 2;
  auto b = OptimizeComesh(*m, options, nullptr, progress, &r2);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(sliding_stages, 2);
  EXPECT_EQ(a->triangles, b->triangles);
  EXPECT_EQ(a->shapes, b->shapes);
  EXPECT_EQ(r1.objective_after, r2.objective_after);
  EXPECT_EQ(r1.inner, r2.inner);
}

TEST(ComeshOptimizerTest, ObjectiveDoesNotDependOnThreadCount) {
  Multimesh m = SquareToHexagon(70);
  std::vector<Points> g1, g3;
  ComeshEnergies e1, e3;
  auto o1 = ComeshObjective::Create(m.triangles, m.shapes, 0.5, 1);
  auto o3 = ComeshObjective::Create(m.triangles, m.shapes, 0.5, 3);
  ASSERT_TRUE(o1.ok() && o3.ok());
  EXPECT_EQ(o1->Evaluate(m.shapes, &g1, &e1), o3->Evaluate(m.shapes, &g3, &e3));
  EXPECT_EQ(g1, g3);
  EXPECT_EQ(e1.map, e3.map);
}

TEST(ComeshOptimizerTest, BlendingAndCuringKeepEveryIterateValid) {
  const Multimesh m = SquareToHexagon(10);
  ComeshOptions options;
  options.blend = 1.0;
  options.cure = true;
  options.max_outer = 0;
  // The audit's objective is the plain one, which outline sliding (areas changing across the
  // hexagon's soft corners, see above) does not descend.
  options.slide_outline = false;
  IterateAudit audit;
  ComeshReport report;
  auto out = audit.Run(m, options, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(audit.inverted, 0);
  EXPECT_EQ(audit.increases, 0);
  EXPECT_GT(report.inner, 5);
  EXPECT_LT(report.objective_after, report.objective_before);
}

TEST(ComeshOptimizerTest, CancelDuringOuterLoopStopsWithCancelled) {
  auto m = BuiltSquareToHexagon(32);
  ASSERT_TRUE(m.ok()) << m.status();
  CancelToken cancel;
  ProgressFn progress = [&](const std::string&, double, const std::string& detail) {
    if (detail.rfind("outer", 0) == 0) cancel.Cancel();
  };
  auto out = OptimizeComesh(*m, ComeshOptions{}, &cancel, progress, nullptr);
  EXPECT_TRUE(absl::IsCancelled(out.status())) << out.status();
}

TEST(ComeshOptimizerTest, RejectsBadOuterOptions) {
  const Multimesh m = SquareToHexagon(4);
  ComeshOptions options;
  options.max_outer = -1;
  EXPECT_EQ(OptimizeComesh(m, options, nullptr, nullptr, nullptr).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(ComeshOptimizerTest, RejectsBadMipsDamping) {
  const Multimesh m = SquareToHexagon(4);
  for (double damping : {-0.5, std::nan(""), std::numeric_limits<double>::infinity()}) {
    ComeshOptions options;
    options.mips_damping = damping;
    const absl::Status st = OptimizeComesh(m, options, nullptr, nullptr, nullptr).status();
    EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument) << damping;
    EXPECT_NE(st.message().find("mips_damping"), std::string::npos) << st;
  }
}

TEST(ComeshOptimizerTest, RejectsBadRelaxOptions) {
  const Multimesh m = SquareToHexagon(4);
  for (int which = 0; which < 4; ++which) {
    ComeshOptions options;
    if (which == 0) options.relax_steps = -1;
    if (which == 1) options.relax_max_vertices = -1;
    if (which == 2) options.relax_over_mean = std::nan("");
    if (which == 3) options.relax_fraction = std::nan("");
    const absl::Status st = OptimizeComesh(m, options, nullptr, nullptr, nullptr).status();
    EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument) << which;
    EXPECT_NE(st.message().find("relax"), std::string::npos) << st;
  }
}

// The inner loop with the local relaxation made to pick many vertices after every short step:
// no iterate inverts or raises the objective (evaluated afresh), and the objective and energies
// the optimizer tracked through the relaxations are those of its result.
TEST(ComeshOptimizerTest, RelaxationKeepsIteratesValidAndTrackedEnergiesExact) {
  const Multimesh m = SquareToHexagon(12);
  auto objective = ComeshObjective::Create(m.triangles, m.shapes, 0.5);
  ASSERT_TRUE(objective.ok());
  ComeshOptions options;
  options.max_outer = 0;
  options.relax_fraction = 1e-9;
  options.relax_over_mean = 0.0;
  options.relax_max_vertices = 64;
  IterateAudit audit;
  ComeshReport report;
  auto out = audit.Run(m, options, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GT(report.phase_seconds.relax, 0.0);  // it ran
  EXPECT_EQ(audit.inverted, 0);
  EXPECT_EQ(audit.increases, 0);
  ComeshEnergies fresh;
  const double f = objective->Evaluate(out->shapes, nullptr, &fresh);
  EXPECT_NEAR(report.objective_after, f, 1e-11 * f);
  EXPECT_NEAR(report.map_energy, fresh.map, 1e-11 * fresh.map);
  EXPECT_NEAR(report.mesh_energy, fresh.mesh, 1e-11 * fresh.mesh);
  EXPECT_LT(report.objective_after, report.objective_before);
}

void ExpectResumedFrom(const Multimesh& m, ComeshOptions options,
                       const std::vector<ComeshCheckpoint>& checkpoints,
                       const std::vector<std::pair<int, std::vector<Points>>>& iterates,
                       const ComeshReport& full, const Multimesh& uninterrupted_mesh,
                       const ComeshCheckpoint& middle);

// Resuming from a checkpoint in the middle gives the uninterrupted run, bit for bit: the same
// multimesh, the same report (seconds aside), the same iterates numbered on.
// `guard`: ComeshOptions::outline_tolerance and outline_reference (else the guard is off).
void ExpectResumedRunEqualsUninterrupted(const absl::StatusOr<Multimesh>& m,
                                         bool slide_outline = false,
                                         const ComeshOptions* guard = nullptr,
                                         double slide_window = ComeshOptions{}.slide_window) {
  ASSERT_TRUE(m.ok()) << m.status();
  ComeshOptions options;
  options.slide_outline = slide_outline;
  options.slide_window = slide_window;
  options.outline_tolerance = guard != nullptr ? guard->outline_tolerance : 0.0;
  if (guard != nullptr) options.outline_reference = guard->outline_reference;
  // Short runs between passes and no outer tolerance: several passes, so that a checkpoint in
  // the middle has passes (and the outer stops) after it.
  options.outer_inner_iterations = 5;
  options.outer_tolerance = 0.0;
  std::vector<ComeshCheckpoint> checkpoints;
  std::vector<std::pair<int, std::vector<Points>>> iterates;
  options.on_checkpoint = [&](const ComeshCheckpoint& c) { checkpoints.push_back(c); };
  options.on_iterate = [&](int i, const std::vector<Points>& x) { iterates.emplace_back(i, x); };
  ComeshReport full;
  auto uninterrupted = OptimizeComesh(*m, options, nullptr, nullptr, &full);
  ASSERT_TRUE(uninterrupted.ok()) << uninterrupted.status();
  ASSERT_GE(checkpoints.size(), 3u) << "need a checkpoint in the middle";
  ASSERT_EQ(static_cast<int>(checkpoints.size()), full.outer);
  for (size_t k = 0; k < checkpoints.size(); ++k) EXPECT_EQ(checkpoints[k].outer, int(k) + 1);

  // The middle checkpoint, and with outline sliding the first of its stage too (the run
  // without sliding comes first: OptimizeComesh's stages).
  std::vector<size_t> starts = {checkpoints.size() / 2};
  if (slide_outline) {
    size_t first = 0;
    while (first < checkpoints.size() && checkpoints[first].stage == 0) ++first;
    ASSERT_LT(first, checkpoints.size()) << "no pass while sliding along the outlines";
    ASSERT_GT(first, 0u) << "no pass before sliding along the outlines";
    starts.push_back(first);
  }
  for (size_t start : starts) {
    SCOPED_TRACE(absl::StrCat("resumed after pass ", start + 1, " of ", checkpoints.size()));
    ExpectResumedFrom(*m, options, checkpoints, iterates, full, *uninterrupted, checkpoints[start]);
  }
}

void ExpectResumedFrom(const Multimesh& m, ComeshOptions options,
                       const std::vector<ComeshCheckpoint>& checkpoints,
                       const std::vector<std::pair<int, std::vector<Points>>>& iterates,
                       const ComeshReport& full, const Multimesh& uninterrupted_mesh,
                       const ComeshCheckpoint& middle) {
  const Multimesh* uninterrupted = &uninterrupted_mesh;
  ASSERT_GT(middle.inner, 0);
  std::vector<ComeshCheckpoint> later;
  std::vector<std::pair<int, std::vector<Points>>> resumed_iterates;
  options.on_checkpoint = [&](const ComeshCheckpoint& c) { later.push_back(c); };
  options.on_iterate = [&](int i, const std::vector<Points>& x) {
    resumed_iterates.emplace_back(i, x);
  };
  options.threads = 1;  // the thread count does not matter either
  ComeshReport rest;
  auto resumed = OptimizeComesh(m, options, nullptr, nullptr, &rest, &middle);
  ASSERT_TRUE(resumed.ok()) << resumed.status();

  EXPECT_EQ(resumed->triangles, uninterrupted->triangles);
  EXPECT_EQ(resumed->shapes, uninterrupted->shapes);  // exact doubles
  EXPECT_EQ(resumed->boundary, uninterrupted->boundary);
  EXPECT_EQ(resumed->boundary_loops, uninterrupted->boundary_loops);
  EXPECT_EQ(resumed->cohesive_edges, uninterrupted->cohesive_edges);
  EXPECT_EQ(resumed->cohesive_closed, uninterrupted->cohesive_closed);
  EXPECT_EQ(rest.inner, full.inner);
  EXPECT_EQ(rest.outer, full.outer);
  EXPECT_EQ(rest.flips, full.flips);
  EXPECT_EQ(rest.collapses, full.collapses);
  EXPECT_EQ(rest.splits, full.splits);
  EXPECT_EQ(rest.energy_evaluations, full.energy_evaluations);
  EXPECT_EQ(rest.objective_trace, full.objective_trace);
  EXPECT_EQ(rest.objective_before, full.objective_before);
  EXPECT_EQ(rest.objective_after, full.objective_after);
  EXPECT_EQ(rest.map_energy, full.map_energy);
  EXPECT_EQ(rest.mesh_energy, full.mesh_energy);
  EXPECT_EQ(rest.vertices_before, full.vertices_before);
  EXPECT_EQ(rest.vertices_after, full.vertices_after);
  EXPECT_EQ(rest.stop_reason, full.stop_reason);
  // The iterates after the checkpoint, numbered on from it, identical.
  ASSERT_EQ(resumed_iterates.size(), iterates.size() - middle.inner);
  for (size_t i = 0; i < resumed_iterates.size(); ++i) {
    EXPECT_EQ(resumed_iterates[i].first, middle.inner + 1 + static_cast<int>(i));
    EXPECT_EQ(resumed_iterates[i].second, iterates[middle.inner + i].second) << "iterate " << i;
  }
  // And the later checkpoints too.
  ASSERT_EQ(later.size(), checkpoints.size() - middle.outer);
  for (size_t k = 0; k < later.size(); ++k) {
    const ComeshCheckpoint& a = later[k];
    const ComeshCheckpoint& b = checkpoints[middle.outer + k];
    EXPECT_EQ(a.outer, b.outer);
    EXPECT_EQ(a.stage, b.stage);
    EXPECT_EQ(a.inner, b.inner);
    EXPECT_EQ(a.pass_start_objective, b.pass_start_objective);
    EXPECT_EQ(a.objective_trace, b.objective_trace);
    EXPECT_EQ(a.mesh.shapes, b.mesh.shapes);
  }
}

// A curved pair built by BuildMultimesh: a circle (96 points) -> a half-disk (a 33-point arc and
// its diameter: two 90-degree corners).
absl::StatusOr<Multimesh> CircleToHalfDisk(int boundary_vertices) {
  Drawing half;
  Points arch;
  for (int k = 0; k <= 32; ++k) {
    const double t = std::numbers::pi * k / 32.0;
    arch.push_back(Point(0.5 + 0.5 * std::cos(t), 0.3 + 0.5 * std::sin(t)));
  }
  half.outlines.push_back({arch});
  // By arc length: on this correspondence the inner runs press a triangle flat, which the sliver
  // test below needs (the feature alignment, the default, pairs the half-disk's corners with
  // points of the circle so that no triangle is pressed flat).
  MultimeshOptions build;
  build.boundary_vertices = boundary_vertices;
  build.correspondence = MultimeshOptions::Correspondence::kArcLength;
  return BuildMultimesh({Ellipse(Point(0.5, 0.5), 0.5, 0.5), half}, build);
}

// A circle -> a 0.9 x 0.3 ellipse (96 points each): no hard point at all.
absl::StatusOr<Multimesh> CircleToEllipse(int boundary_vertices) {
  return BuildDrawings({Ellipse(Point(0.5, 0.5), 0.5, 0.5), Ellipse(Point(0.5, 0.5), 0.9, 0.3)},
                       boundary_vertices);
}

TEST(ComeshOptimizerTest, ResumedFromAMiddleCheckpointEqualsTheUninterruptedRun) {
  ExpectResumedRunEqualsUninterrupted(BuiltSquareToHexagon(160));
}

// The same with curved outlines, resumed before the sliding stage and at its first pass: the
// resumed run goes on in the checkpoint's stage and slides the boundary along the input's
// outlines (not the checkpoint's boundary, whose vertices have already left some polyline
// points).
TEST(ComeshOptimizerTest, ResumedRunSlidesAlongTheInputOutlines) {
  // Unbounded sliding: the circle's vertices travel far, so the sliding stage has passes.
  ExpectResumedRunEqualsUninterrupted(CircleToEllipse(48), /*slide_outline=*/true, nullptr,
                                      /*slide_window=*/0.0);
}

TEST(ComeshOptimizerTest, RejectsAnInvalidCheckpoint) {
  auto m = BuiltSquareToHexagon(24);
  ASSERT_TRUE(m.ok()) << m.status();
  ComeshCheckpoint bad;
  bad.mesh = *m;
  std::swap(bad.mesh.triangles[0][1], bad.mesh.triangles[0][2]);  // inverted
  auto out = OptimizeComesh(*m, ComeshOptions{}, nullptr, nullptr, nullptr, &bad);
  EXPECT_EQ(out.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(out.status().message().find("checkpoint"), std::string::npos);
}

// Curved outlines: every boundary vertex of a circle -> half-disk multimesh is a corner of its
// own polyline, so only outline sliding (ComeshOptions::slide_outline, on by default) lets the
// boundary correspondence move. With it the map energy falls far lower; every boundary vertex stays
// on its shape's input outline; the half-disk's two drawn corners (90 degrees) keep a vertex
// exactly where they were. Without it the boundary is the input's point set, corners in place.
TEST(ComeshOptimizerTest, CurvedOutlinesSlideAlongTheirPolylines) {
  absl::StatusOr<Multimesh> m = CircleToHalfDisk(48);
  ASSERT_TRUE(m.ok()) << m.status();
  ComeshOptions options;
  options.slide_outline = true;
  // The sliding itself, on a fixed 48-vertex outline whose vertices must travel far along the
  // circle: the outline guard (tested below) would hold them to chords within 0.1%, the pairing
  // windows (tested below) to where the build paired them.
  options.outline_tolerance = 0.0;
  options.slide_window = 0.0;
  ComeshReport on, off;
  absl::StatusOr<Multimesh> slid = OptimizeComesh(*m, options, nullptr, nullptr, &on);
  ASSERT_TRUE(slid.ok()) << slid.status();
  options.slide_outline = false;
  absl::StatusOr<Multimesh> kept = OptimizeComesh(*m, options, nullptr, nullptr, &off);
  ASSERT_TRUE(kept.ok()) << kept.status();
  EXPECT_LT(on.map_energy, off.map_energy - 0.1) << on.map_energy << " vs " << off.map_energy;
  EXPECT_LT(on.objective_after, off.objective_after);
  testing::ExpectBoundaryKept(*m, *kept);
  EXPECT_TRUE(ValidateMultimesh(*slid).ok()) << ValidateMultimesh(*slid);
  const std::vector<int>& loop = m->boundary_loops.at(0);
  const size_t n = loop.size();
  int corners = 0;
  for (int s = 0; s < 2; ++s) {
    const Points& x = m->shapes[s];
    const Points& y = slid->shapes[s];
    EXPECT_EQ(CountInverted(slid->triangles, y), 0) << "shape " << s;
    for (int v : slid->boundary) {
      double d = std::numeric_limits<double>::infinity();
      for (size_t k = 0; k < n; ++k) {
        d = std::min(d, testing::DistanceToSegment(y[v], x[loop[k]], x[loop[(k + 1) % n]]));
      }
      EXPECT_LE(d, 1e-9) << "shape " << s << " vertex " << v << " left its outline";
    }
    for (size_t k = 0; k < n; ++k) {
      const Point in = x[loop[k]] - x[loop[(k + n - 1) % n]];
      const Point out = x[loop[(k + 1) % n]] - x[loop[k]];
      if (in.dot(out) >= std::cos(options.outline_corner_degrees * std::numbers::pi / 180.0) *
                             in.norm() * out.norm()) {
        continue;
      }
      ++corners;
      double nearest = std::numeric_limits<double>::infinity();
      for (int v : slid->boundary) nearest = std::min(nearest, (y[v] - x[loop[k]]).norm());
      EXPECT_EQ(nearest, 0.0) << "corner " << k << " of shape " << s;
    }
  }
  EXPECT_EQ(corners, 2);  // the half-disk's
}

// Sliver removal, the optimizer's last step: on the circle -> half-disk pair the inner runs press
// a triangle flat in both shapes (worst quality ~1e-5 without the step); with it (the default)
// every triangle of the result is above min_quality, the report says what it found and the worst
// quality it left, and the map energy stays within 1% of the run without.
TEST(ComeshOptimizerTest, RemovesTheSliversInnerRunsLeave) {
  absl::StatusOr<Multimesh> m = CircleToHalfDisk(48);
  ASSERT_TRUE(m.ok()) << m.status();
  ComeshOptions options;
  options.slide_window = 0.0;  // the long slides that press triangles flat
  ComeshReport with, without;
  absl::StatusOr<Multimesh> cleaned = OptimizeComesh(*m, options, nullptr, nullptr, &with);
  ASSERT_TRUE(cleaned.ok()) << cleaned.status();
  options.min_quality = 0.0;
  absl::StatusOr<Multimesh> raw = OptimizeComesh(*m, options, nullptr, nullptr, &without);
  ASSERT_TRUE(raw.ok()) << raw.status();
  EXPECT_LT(WorstQuality(*raw), 0.02);
  EXPECT_EQ(without.slivers, 0);  // not looked for
  EXPECT_EQ(without.worst_quality, WorstQuality(*raw));
  EXPECT_GE(with.slivers, 1);
  EXPECT_GE(with.sliver_operations, 1);
  EXPECT_GE(WorstQuality(*cleaned), ComeshOptions().min_quality);
  EXPECT_EQ(with.worst_quality, WorstQuality(*cleaned));
  EXPECT_TRUE(ValidateMultimesh(*cleaned).ok()) << ValidateMultimesh(*cleaned);
  EXPECT_NEAR(with.map_energy, without.map_energy, 0.01 * without.map_energy);
  // The report's energies are the result's.
  absl::StatusOr<ComeshObjective> objective =
      ComeshObjective::Create(cleaned->triangles, cleaned->shapes, options.map_weight);
  ASSERT_TRUE(objective.ok()) << objective.status();
  ComeshEnergies energies;
  objective->Evaluate(cleaned->shapes, nullptr, &energies);
  EXPECT_NEAR(with.map_energy, energies.map, 1e-12);
  EXPECT_NEAR(with.mesh_energy, energies.mesh, 1e-12);
}

// Outline sliding as a property over random drawings: pairs of wavy blobs (random harmonics),
// the second with a sharp spike (two corners of its outline), three of them with a third shape.
// Whatever the seed: no accepted iterate inverts a triangle in any shape, every topology pass
// hands on a valid multimesh, every boundary vertex stays on its input outline and every sharp
// corner keeps its place, and the map energy does not rise.
TEST(ComeshOptimizerTest, RandomCurvedDrawingsSlideSafely) {
  auto blob = [](unsigned seed, bool spike) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> amplitude(-0.06, 0.06), phase(0.0, 2 * std::numbers::pi);
    double a[4], p[4];
    for (int k = 0; k < 4; ++k) a[k] = amplitude(rng), p[k] = phase(rng);
    Drawing d;
    Points outline;
    const int n = 90;
    for (int i = 0; i < n; ++i) {
      const double t = 2.0 * std::numbers::pi * i / n;
      double r = 0.5;
      for (int k = 0; k < 4; ++k) r += a[k] * std::cos((k + 2) * t + p[k]);
      if (spike && i == n / 4) r += 0.25;
      outline.push_back(Point(0.5 + r * std::cos(t), 0.5 + r * std::sin(t)));
    }
    d.outlines.push_back({outline});
    return d;
  };
  for (unsigned seed = 1; seed <= 6; ++seed) {
    std::vector<Drawing> drawings = {blob(seed, false), blob(100 + seed, true)};
    if (seed % 2 == 0) drawings.push_back(blob(200 + seed, false));
    MultimeshOptions build;
    build.boundary_vertices = 40;
    absl::StatusOr<Multimesh> m = BuildMultimesh(drawings, build);
    ASSERT_TRUE(m.ok()) << "seed " << seed << ": " << m.status();
    ComeshOptions options;
    options.slide_outline = true;
    options.max_outer = 4;
    int bad = 0;
    std::vector<Triangle> triangles = m->triangles;  // of the current topology
    options.on_checkpoint = [&](const ComeshCheckpoint& checkpoint) {
      triangles = checkpoint.mesh.triangles;
      EXPECT_TRUE(ValidateMultimesh(checkpoint.mesh).ok()) << "seed " << seed;
    };
    options.on_iterate = [&](int, const std::vector<Points>& shapes) {
      for (const Points& x : shapes) bad += testing::CountNonPositive(triangles, x);
    };
    ComeshReport report;
    absl::StatusOr<Multimesh> out = OptimizeComesh(*m, options, nullptr, nullptr, &report);
    ASSERT_TRUE(out.ok()) << "seed " << seed << ": " << out.status();
    EXPECT_EQ(bad, 0) << "seed " << seed;
    EXPECT_TRUE(ValidateMultimesh(*out).ok()) << "seed " << seed << ": " << ValidateMultimesh(*out);
    EXPECT_LE(report.map_energy, report.map_energy_before) << "seed " << seed;
    testing::ExpectBoundaryKept(*m, *out, options.outline_corner_degrees);
  }
}

// Three or more shapes whose whole outlines slide (round drawings: no hard point anywhere) leave
// the Laplacian preconditioner of those shapes' vertices without a Dirichlet vertex. Its solve must
// not blow the constant (a translation the loop of sliders cannot follow) up into the direction:
// that made every step a tiny fraction of a huge direction, and the principles_timing example
// ended 1.2% above its run without outline sliding. Three circles (moved and scaled: every map
// can be conformal) must end no higher with sliding than without (4.5767 against 4.5845; 4.5916
// before).
TEST(ComeshOptimizerTest, WholeOutlinesSlidingInThreeShapesStillConverge) {
  absl::StatusOr<Multimesh> m =
      BuildDrawings({Ellipse(Point(0.5, 0.5), 0.5, 0.5), Ellipse(Point(1.5, 0.6), 0.5, 0.5),
                     Ellipse(Point(0.8, 0.3), 0.4, 0.4)},
                    40);
  ASSERT_TRUE(m.ok()) << m.status();
  ComeshOptions options;
  ASSERT_LT(options.hessian_max_shapes, 3);  // the Laplacian preconditioner's case
  ComeshReport on, off;
  options.slide_outline = true;
  absl::StatusOr<Multimesh> slid = OptimizeComesh(*m, options, nullptr, nullptr, &on);
  ASSERT_TRUE(slid.ok()) << slid.status();
  options.slide_outline = false;
  ASSERT_TRUE(OptimizeComesh(*m, options, nullptr, nullptr, &off).ok());
  EXPECT_LE(on.objective_after, off.objective_after)
      << on.objective_after << " vs " << off.objective_after;
  EXPECT_LT(on.map_energy, 2.0 + 1e-3);
}

// Correspondence marks stay pinned (issue "Comesh optimization"): square -> hexagon built with a
// mark at the middle of the square's bottom and top sides, matched to the middle of the
// hexagon's bottom and top sides. Both lie on straight stretches in both shapes, where every
// other boundary vertex slides; the marks' vertices stay where they were, in both shapes,
// through inner runs and topology passes (corner swaps included), and are listed as pinned in
// the result. The same multimesh with its pins dropped moves them.
TEST(ComeshOptimizerTest, CorrespondenceMarksStayPinned) {
  MultimeshOptions build;
  build.boundary_vertices = 48;
  build.max_edge_relative = 0.08;
  const double h = 0.6 * std::sin(std::numbers::pi / 3.0);
  build.marks = {{Point(0.5, 0.0), Point(0.5, 0.5 - h)}, {Point(0.5, 1.0), Point(0.5, 0.5 + h)}};
  absl::StatusOr<Multimesh> built = BuildMultimesh(
      {testing::UnitSquare(), testing::RegularPolygon(6, 0.6, Point(0.5, 0.5))}, build);
  ASSERT_TRUE(built.ok()) << built.status();
  ASSERT_EQ(built->pinned.size(), 2u);
  std::vector<std::vector<Point>> at(2);
  for (int v : built->pinned) {
    for (int s = 0; s < 2; ++s) at[s].push_back(built->shapes[s][v]);
  }
  ComeshOptions options;
  options.max_outer = 3;
  ComeshReport report;
  absl::StatusOr<Multimesh> out = OptimizeComesh(*built, options, nullptr, nullptr, &report);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GT(report.outer, 0);
  EXPECT_TRUE(ValidateMultimesh(*out).ok()) << ValidateMultimesh(*out);
  testing::ExpectBoundaryKept(*built, *out);
  ASSERT_EQ(out->pinned.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    for (int s = 0; s < 2; ++s) EXPECT_EQ(out->shapes[s][out->pinned[i]], at[s][i]) << i << s;
  }
  Multimesh unpinned = *built;
  unpinned.pinned.clear();
  absl::StatusOr<Multimesh> free = OptimizeComesh(unpinned, options, nullptr, nullptr, nullptr);
  ASSERT_TRUE(free.ok()) << free.status();
  int moved = 0;
  for (size_t i = 0; i < 2; ++i) {
    for (int s = 0; s < 2; ++s) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Point& p : free->shapes[s]) nearest = std::min(nearest, (p - at[s][i]).norm());
      moved += nearest > 1e-9;
    }
  }
  EXPECT_GT(moved, 0) << "without pins the marks' vertices would have stayed anyway";
}

// Distance from p to the nearest segment of the closed polylines `loops`.
double DistanceToLoops(const Point& p, const std::vector<Points>& loops) {
  double best = std::numeric_limits<double>::infinity();
  for (const Points& loop : loops) {
    for (size_t k = 0; k < loop.size(); ++k) {
      best = std::min(best, testing::DistanceToSegment(p, loop[k], loop[(k + 1) % loop.size()]));
    }
  }
  return best;
}

// The Hausdorff distance (both ways, over the polylines' points) between shape s's boundary
// loops and drawing d's outlines, relative to the drawing's bounding-box diagonal.
double KeyDeviation(const Multimesh& m, int s, const Drawing& d) {
  std::vector<Points> key, drawn;
  for (const std::vector<int>& loop : m.boundary_loops) {
    Points& points = key.emplace_back();
    for (int v : loop) points.push_back(m.shapes[s][v]);
  }
  Point lo = Point::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Outline& o : d.outlines) {
    drawn.push_back(o.points);
    for (const Point& p : o.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  double worst = 0.0;
  for (const Points& loop : drawn) {
    for (const Point& p : loop) worst = std::max(worst, DistanceToLoops(p, key));
  }
  for (const Points& loop : key) {
    for (const Point& p : loop) worst = std::max(worst, DistanceToLoops(p, drawn));
  }
  return worst / (hi - lo).norm();
}

// A drop (body of radius sx x sy) whose tip is a small round cap drawn with many small turns,
// each below the sliders' 25-degree hard corners.
Drawing Drop(double sx, double sy) {
  Drawing d;
  Points outline;
  const int body = 60, cap = 24;
  // The body: a circle of radius 1 from angle -60 to 240 degrees (y down), then two straight
  // sides to a cap of radius 0.08 at the top.
  for (int i = 0; i <= body; ++i) {
    const double t = (-60.0 + 300.0 * i / body) * std::numbers::pi / 180.0;
    outline.push_back(Point(sx * std::cos(t), sy * (1.0 + std::sin(t))));
  }
  const Point tip(0.0, sy * -1.2);
  for (int i = 0; i <= cap; ++i) {
    const double t = (210.0 + 120.0 * i / cap) * std::numbers::pi / 180.0;
    outline.push_back(tip + Point(0.08 * sx * std::cos(t), 0.08 * sy * std::sin(t)));
  }
  d.outlines.push_back({outline});
  return d;
}

// A drop -> the same drop squashed wide. Built to the default outline tolerance
// (0.1% of the diagonal), then optimized: without the outline guard the sliders leave the cap's
// points and the chords cut the tip off; with it (the default, against the drawings) every key
// stays within the tolerance of its drawing, and the run still lowers the objective.
TEST(ComeshOptimizerTest, OutlineGuardKeepsTheKeysWithinTheBuildTolerance) {
  const std::vector<Drawing> drawings = {Drop(1.0, 1.0), Drop(1.6, 0.7)};
  absl::StatusOr<Multimesh> m = BuildMultimesh(drawings, MultimeshOptions{});
  ASSERT_TRUE(m.ok()) << m.status();
  const double tolerance = MultimeshOptions{}.boundary_tolerance;
  for (int s = 0; s < 2; ++s) ASSERT_LE(KeyDeviation(*m, s, drawings[s]), tolerance * 1.001);

  ComeshOptions options;
  options.max_outer = 6;
  options.slide_window = 0.0;  // the long slides whose chords cut the tip
  for (const Drawing& d : drawings) options.outline_reference.push_back({d.outlines[0].points});
  ComeshOptions unguarded = options;
  unguarded.outline_tolerance = 0.0;
  ComeshReport report, unguarded_report;
  absl::StatusOr<Multimesh> guarded = OptimizeComesh(*m, options, nullptr, nullptr, &report);
  absl::StatusOr<Multimesh> free =
      OptimizeComesh(*m, unguarded, nullptr, nullptr, &unguarded_report);
  ASSERT_TRUE(guarded.ok()) << guarded.status();
  ASSERT_TRUE(free.ok()) << free.status();
  double free_worst = 0.0;
  for (int s = 0; s < 2; ++s) {
    free_worst = std::max(free_worst, KeyDeviation(*free, s, drawings[s]));
    EXPECT_LE(KeyDeviation(*guarded, s, drawings[s]), tolerance * 1.001) << "shape " << s;
  }
  EXPECT_GT(free_worst, 1.5 * tolerance);  // the case needs the guard
  EXPECT_LT(report.objective_after, report.objective_before);
  EXPECT_TRUE(ValidateMultimesh(*guarded).ok());
}

// The largest distance (arc length on shape 1's outline) between where `out` puts a boundary
// vertex in shape 1 and where `input`'s boundary correspondence pairs its place in shape 0, in
// mean boundary edge lengths of shape 1.
double PairingDrift(const Multimesh& input, const Multimesh& out) {
  const BoundaryPairing pairing(input, 1e-12);
  double drift = 0.0, edges = 0.0;
  int count = 0;
  for (const std::vector<int>& loop : out.boundary_loops) {
    const int n = static_cast<int>(loop.size());
    for (int k = 0; k < n; ++k) {
      const int prev = loop[(k + n - 1) % n], v = loop[k], next = loop[(k + 1) % n];
      edges += (out.shapes[1][next] - out.shapes[1][v]).norm();
      ++count;
      const std::optional<BoundaryPairing::Window> w =
          pairing.WindowOf(out.shapes, 1, v, prev, next);
      EXPECT_TRUE(w.has_value()) << "vertex " << v << " left the input's outline";
      if (w) drift = std::max(drift, w->hi - w->lo);
    }
  }
  return drift / (edges / count);
}

// Sliders keep the pairing the build made (ComeshOptions::slide_window): an arrow whose right
// part is stretched, paired corner to corner by the build. Unbounded, the map energy slides
// vertices about an edge away from their paired places (toward a conformal but area-distorting
// pairing; measured 1.06 edges); with the windows none ends up half an edge away (0.17).
TEST(ComeshOptimizerTest, SlidersKeepTheBuiltPairing) {
  auto arrow = [](double stretch) {
    Points p = {{0, 40}, {220, 40}, {220, 0}, {320, 70}, {220, 140}, {220, 100}, {0, 100}};
    for (Point& q : p) q.x() = q.x() < 160 ? q.x() : 160 + stretch * (q.x() - 160);
    return Drawing{{Outline{p}}};
  };
  absl::StatusOr<Multimesh> m = BuildMultimesh({arrow(1.0), arrow(1.8)}, MultimeshOptions{});
  ASSERT_TRUE(m.ok()) << m.status();
  ComeshOptions options;
  options.threads = 1;
  options.slide_window = 0.15;
  absl::StatusOr<Multimesh> kept = OptimizeComesh(*m, options, nullptr, nullptr, nullptr);
  options.slide_window = 0.0;
  absl::StatusOr<Multimesh> free = OptimizeComesh(*m, options, nullptr, nullptr, nullptr);
  ASSERT_TRUE(kept.ok()) << kept.status();
  ASSERT_TRUE(free.ok()) << free.status();
  const double kept_drift = PairingDrift(*m, *kept), free_drift = PairingDrift(*m, *free);
  EXPECT_LT(kept_drift, 0.5) << free_drift;
  EXPECT_GT(free_drift, 0.75) << kept_drift;
  EXPECT_TRUE(ValidateMultimesh(*kept).ok()) << ValidateMultimesh(*kept);
}

// A run with the guard resumed from a checkpoint of its sliding stage is the uninterrupted run,
// with the sliders unbounded and kept to the built pairing (ComeshOptions::slide_window).
TEST(ComeshOptimizerTest, ResumedRunWithTheOutlineGuardEqualsTheUninterruptedRun) {
  const std::vector<Drawing> drawings = {Drop(1.0, 1.0), Drop(1.6, 0.7)};
  ComeshOptions guard;
  for (const Drawing& d : drawings) guard.outline_reference.push_back({d.outlines[0].points});
  for (const double window : {0.0, 0.15}) {
    SCOPED_TRACE(::testing::Message() << "slide_window " << window);
    ExpectResumedRunEqualsUninterrupted(BuildMultimesh(drawings, MultimeshOptions{}),
                                        /*slide_outline=*/true, &guard, window);
  }
}

}  // namespace
}  // namespace inbetween::solver
